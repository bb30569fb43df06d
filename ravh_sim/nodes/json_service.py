"""A JSON service (``AddDiagnostics`` carrying JSON text both ways) that answers every request waiting
for it at once: the executor takes one request per service per wait, so a burst faster than the node's
ticks would otherwise pile up in the queue, and rclpy would drop the oldest without a reply."""
from __future__ import annotations

from collections.abc import Callable

from diagnostic_msgs.srv import AddDiagnostics
from rclpy.node import Node

from ravh_msgs_py.query import MAX_REQUEST_CHARS
from ravh_sim.nodes.common import SERVICE_QOS, SERVICE_QUEUE, return_freed_memory

Handler = Callable[[AddDiagnostics.Request, AddDiagnostics.Response], AddDiagnostics.Response]


def json_service(node: Node, name: str, handler: Handler, on_batch: Callable[[], None]) -> None:
    """Serve ``name`` with ``handler``; ``on_batch`` runs before each batch of requests that wait together."""
    def answer(request: AddDiagnostics.Request, response: AddDiagnostics.Response) -> AddDiagnostics.Response:
        response = handler(request, response)
        _forget_if_oversized(request)
        return response

    def callback(request: AddDiagnostics.Request, response: AddDiagnostics.Response) -> AddDiagnostics.Response:
        on_batch()
        response = answer(request, response)
        for _ in range(SERVICE_QUEUE):
            with service.handle:
                waiting, header = service.handle.service_take_request(AddDiagnostics.Request)
            if header is None:
                break
            service.send_response(answer(waiting, AddDiagnostics.Response()), header)
        return response
    service = node.create_service(AddDiagnostics, name, callback, qos_profile=SERVICE_QOS)


def _forget_if_oversized(request: AddDiagnostics.Request) -> None:
    """After an oversized request (refused by its length) drop its text and return the memory it took."""
    if len(request.load_namespace) > MAX_REQUEST_CHARS:
        request.load_namespace = ""
        return_freed_memory()
