"""What every ravh_sim node shares: QoS profiles, DDS set-up and a clean spin/shutdown.

QoS follows the guide's rules: sensors are RELIABLE (a recorder must not lose frames; best-effort
subscribers still match), maps and other once-published facts are RELIABLE + TRANSIENT_LOCAL so late
subscribers get them. Nodes stop cleanly on SIGINT and SIGTERM (Fast DDS leaves shared-memory files
behind on SIGKILL).
"""
from __future__ import annotations

import ctypes
import os
import signal
import sys
import time
from collections.abc import Callable

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from ravh_sim.paths import FASTDDS_PROFILE

SIM_LOST_S = 8.0        # wall seconds without /clock after which a sim counts as gone
STOP_LATENCY_S = 0.1    # longest a spinning node takes to notice SIGINT/SIGTERM
DRAIN_S = 10.0          # longest a stopping node spends finishing the requests it took

# Sensor topics carry captures too: a burst of captures (requests that reach the sim together) must fit
# the history at both ends while a loaded recorder catches up, or a reliable writer drops the oldest
# (seen once under load: a burst of 7 lost its last two captures' images with a depth of 5).
SENSOR_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=12, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)
STATE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
# capture hand-over acknowledgements: none may be lost, and there are few of them
HANDOVER_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.VOLATILE)
# "capture stored" confirmations: latched, so a behaviour whose subscription the recorder's publisher
# matched only after the first capture still gets its confirmation (a behaviour holds one at a time)
RECORDED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100, reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL)
# service requests waiting while the node steps: rclpy's default keeps 10 and silently drops older ones
# under a burst (the client then waits for a reply that never comes); the JSON services also answer
# every queued request in one go (SimNode), refusing with "busy" what they cannot do now
SERVICE_QUEUE = 256
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=SERVICE_QUEUE,
                         reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
COMMAND_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)


def ros_domain_id(pick: int) -> tuple[str, str]:
    """The ROS_DOMAIN_ID to run on and how it was chosen: the user's when set; otherwise one derived
    from ``pick`` (a pid...), so parallel raids and test runs on one machine do not hear each other."""
    user = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if user:
        return user, "from the environment"
    return str(1 + pick % 200), "chosen automatically; set ROS_DOMAIN_ID to choose"


class SimWatchdog:
    """Notices a sim that went away: no /clock for :data:`SIM_LOST_S` wall seconds once one arrived.

    Nodes that run on sim time would otherwise wait for ever when the sim dies; the check runs on a
    wall-clock timer and raises :class:`UserError`, which ends the node's spin with one clear line
    and a non-zero exit (run_node). Silence is counted in checks as well as in seconds, so a node
    that itself got no CPU for a while (a loaded machine) does not blame the sim: its queued /clock
    messages are handled in the same spin as its overdue check."""

    CHECK_S = 0.5

    def __init__(self, node) -> None:
        from rclpy.clock import Clock, ClockType
        from rosgraph_msgs.msg import Clock as ClockMsg

        from ravh_msgs_py import names as n
        self._last: float | None = None
        self._silent_checks = 0
        node.create_subscription(ClockMsg, n.CLOCK, self._on_clock,
                                 QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
        node.create_timer(self.CHECK_S, self._check, clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _on_clock(self, _msg) -> None:
        self._last, self._silent_checks = time.monotonic(), 0

    def _check(self) -> None:
        from ravh_sim.errors import UserError
        self._silent_checks += 1
        if self._last is not None and time.monotonic() - self._last > SIM_LOST_S \
                and self._silent_checks * self.CHECK_S >= SIM_LOST_S:
            raise UserError(f"lost the sim: no /clock for {SIM_LOST_S:.0f} s (did `ravh sim` stop?)")


def use_large_message_transport() -> None:
    """Point Fast DDS at our profile (16 MiB shared-memory segments) unless the user chose one.

    Measured here: a 640x480 rgb8 image takes ~13.5 ms with the default 512 KiB segment and
    best-effort subscribers lose ~40 % of frames; with this profile ~2.7 ms and no loss.
    Must run before rclpy.init() (the participant reads it when created).
    """
    if "FASTRTPS_DEFAULT_PROFILES_FILE" not in os.environ and FASTDDS_PROFILE.exists():
        os.environ["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(FASTDDS_PROFILE)


def return_freed_memory() -> None:
    """Hand freed heap pages back to the OS (glibc's malloc_trim; nothing elsewhere). glibc keeps what
    a large request freed for reuse: measured here, each oversized service request (10 MB of JSON,
    refused by its length) would leave the sim ~10 MB bigger for the rest of its life."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


class StopSignals:
    """SIGINT and SIGTERM as a request to stop that the spin loop checks, not an exception raised
    wherever Python happens to be.

    rclpy's own handler raises KeyboardInterrupt in the main thread (and shuts the context down from
    another thread while callbacks still run). A KeyboardInterrupt raised while rclpy's C++ converts a
    taken message to Python is swallowed by pybind11 and comes out as "RuntimeError: Unable to convert
    call argument '0' to Python object": a node stopped with Ctrl-C then exits 1 with a traceback (a
    loaded machine makes that instant likelier). While the node is being built (it may wait for the
    sim) a signal still raises KeyboardInterrupt; once it spins, a signal only sets :attr:`requested`.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.requested = False
        self.interrupting = True            # raise KeyboardInterrupt (only before the node spins)
        self._previous = {sig: signal.signal(sig, self._handle) for sig in self.SIGNALS}

    def _handle(self, _signum, _frame) -> None:
        self.requested = True
        if self.interrupting:
            raise KeyboardInterrupt

    def restore(self) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)


def spin_until_stopped(node, stop: StopSignals) -> None:
    """Spin ``node`` until a stop signal, or until its ``finished`` future (behaviours that end) is done.
    rcl_wait does not return on a signal, so the wait is bounded by :data:`STOP_LATENCY_S`."""
    import rclpy
    executor = rclpy.get_global_executor()
    executor.add_node(node)
    finished = getattr(node, "finished", None)
    stop.interrupting = False
    while not stop.requested and not (finished is not None and finished.done()):
        executor.spin_once(timeout_sec=STOP_LATENCY_S)
    # Requests the node took before the stop are answered, not dropped (a capture whose frame is still
    # rendering is published and replied to), within a bound.
    in_flight = getattr(node, "in_flight", None)
    deadline = time.monotonic() + DRAIN_S
    while in_flight is not None and in_flight() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=STOP_LATENCY_S)


def run_node(make_node: Callable[[list[str]], Node], argv: list[str] | None = None) -> int:
    """rclpy.init, build the node, spin until SIGINT/SIGTERM, shut down cleanly. User errors and write
    errors (a full disk, also while closing) print one line and return 2; else the node's ``exit_code``
    after close (0 unless it failed)."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from ravh_sim.errors import UserError

    use_large_message_transport()
    args = sys.argv if argv is None else argv
    stop = StopSignals()
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    failed = False
    try:
        node = make_node(rclpy.utilities.remove_ros_args(args)[1:])
        spin_until_stopped(node, stop)
    except (UserError, OSError) as e:
        failed = _print_error(e)
    except KeyboardInterrupt:
        pass
    except RuntimeError:
        if not stop.requested:              # else a KeyboardInterrupt that rclpy's C++ turned into this
            raise
    finally:
        stop.interrupting = False           # a second Ctrl-C must not cut close() short
        if node is not None:
            close = getattr(node, "close", None)
            try:
                if close:
                    close()
            except OSError as e:
                failed = failed or _print_error(e)      # the same full disk again: said already
            node.destroy_node()
        rclpy.try_shutdown()
        stop.restore()
    return 2 if failed else getattr(node, "exit_code", 0)


def _print_error(e: Exception) -> bool:
    """One line on stderr for a user error or an OSError (naming the file when known)."""
    if isinstance(e, OSError):
        print(f"ravh: error: {f'{e.filename}: ' if e.filename else ''}{e.strerror or e}", file=sys.stderr)
    else:
        print(f"ravh: error: {e}", file=sys.stderr)
    return True
