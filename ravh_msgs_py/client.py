"""A small Python client for the sim node's JSON services (ground-truth queries, appearance changes).

Usage, inside any rclpy program::

    client = RavhClient(node)
    rooms = client.query("rooms", type="Bedroom")          # the reply's result, or raises QueryError
    client.appearance(sun_angle="night", lights={"ceiling": "on"})

rclpy is imported when a client is made, so the rest of ravh_msgs_py stays importable without ROS.
"""
from __future__ import annotations

import json
from typing import Any

from ravh_msgs_py import names
from ravh_msgs_py.query import INTERNAL, QueryError, request


class RavhClient:
    def __init__(self, node: Any, timeout: float = 10.0) -> None:
        from diagnostic_msgs.srv import AddDiagnostics
        self._node = node
        self._timeout = timeout
        self._srv_type = AddDiagnostics
        self._query = node.create_client(AddDiagnostics, names.QUERY_SERVICE)
        self._appearance = node.create_client(AddDiagnostics, names.APPEARANCE_SERVICE)

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
        """Apply appearance changes (see ravh_msgs_py.appearance); returns what changed."""
        return _result(self.call_json(self._appearance, json.dumps(changes)))


def _result(reply: dict[str, Any]) -> Any:
    if reply.get("ok"):
        return reply["result"]
    err = reply.get("error", {})
    raise QueryError(err.get("code", INTERNAL), err.get("message", "failed"), err.get("valid"))
