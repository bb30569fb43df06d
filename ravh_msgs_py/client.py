"""A small Python client for the sim node's JSON services (ground-truth queries, appearance changes).

Usage, inside any rclpy program::

    client = RavhClient(node)
    rooms = client.query("rooms", type="Bedroom")          # the reply's result, or raises QueryError
    client.appearance(sun_angle="night", lights={"ceiling": "on"})

rclpy is imported when a client is made, so the rest of ravh_msgs_py stays importable without ROS.
"""
from __future__ import annotations

import json
import time
from typing import Any

from ravh_msgs_py import names
from ravh_msgs_py.query import BUSY, INTERNAL, QueryError, request

RESPONSE_QUEUE = 256          # replies held until the caller spins (rclpy's default 10 drops a burst's)
BUSY_RETRY_S = (0.1, 1.0)     # first and longest wait before sending a refused ("busy") change again


class RavhClient:
    def __init__(self, node: Any, timeout: float = 10.0) -> None:
        from diagnostic_msgs.srv import AddDiagnostics
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        self._node = node
        self._timeout = timeout
        self._srv_type = AddDiagnostics
        qos = QoSProfile(depth=RESPONSE_QUEUE, reliability=ReliabilityPolicy.RELIABLE)
        self._query = node.create_client(AddDiagnostics, names.QUERY_SERVICE, qos_profile=qos)
        self._appearance = node.create_client(AddDiagnostics, names.APPEARANCE_SERVICE, qos_profile=qos)

    def wait_for_services(self, timeout: float | None = None) -> bool:
        t = self._timeout if timeout is None else timeout
        return self._query.wait_for_service(timeout_sec=t) and self._appearance.wait_for_service(timeout_sec=t)

    def call_json(self, client: Any, text: str) -> dict[str, Any]:
        """Send one JSON request and return the decoded reply envelope."""
        import rclpy
        req = self._srv_type.Request(load_namespace=text)
        future = client.call_async(req)
        rclpy.spin_until_future_complete(self._node, future, timeout_sec=self._timeout)
        if not future.done() or future.result() is None:
            raise QueryError(INTERNAL, f"no reply from {client.srv_name} within {self._timeout} s")
        return json.loads(future.result().message)

    def query_reply(self, query: str, **args: Any) -> dict[str, Any]:
        return self.call_json(self._query, request(query, **args))

    def query(self, query: str, **args: Any) -> Any:
        """The result of a ground-truth query; a failed query raises :class:`QueryError`."""
        return _result(self.query_reply(query, **args))

    def appearance(self, **changes: Any) -> Any:
        """Apply appearance changes (see ravh_msgs_py.appearance); returns what changed. A change the
        sim refuses as busy (it limits the time changes take from it) is sent again, backing off, until
        the client's timeout; then the QueryError says busy."""
        text, wait = json.dumps(changes), BUSY_RETRY_S[0]
        deadline = time.monotonic() + self._timeout
        while True:
            reply = self.call_json(self._appearance, text)
            if reply.get("ok") or reply.get("error", {}).get("code") != BUSY or time.monotonic() + wait > deadline:
                return _result(reply)
            time.sleep(wait)
            wait = min(2 * wait, BUSY_RETRY_S[1])


def _result(reply: dict[str, Any]) -> Any:
    if reply.get("ok"):
        return reply["result"]
    err = reply.get("error", {})
    raise QueryError(err.get("code", INTERNAL), err.get("message", "failed"), err.get("valid"))
