"""Exceptions carrying the library's result codes (j288/error.h)."""

from __future__ import annotations

from typing import Dict, List

from ._native import LIB

# The names of j288/error.h's codes (python/tests checks this table against the header).
NAMES: Dict[int, str] = {
    0: "J288_OK",
    -1: "J288_ERR_NULL",
    -2: "J288_ERR_BAD_ID",
    -3: "J288_ERR_BAD_STATUS",
    -4: "J288_ERR_NEG_GAIN",
    -5: "J288_ERR_RANGE_TAU",
    -6: "J288_ERR_RANGE_SPEED",
    -7: "J288_ERR_RANGE_POS",
    -8: "J288_ERR_RANGE_KP",
    -9: "J288_ERR_RANGE_KD",
    -10: "J288_ERR_NOT_FINITE",
    -11: "J288_ERR_RANGE",
    -12: "J288_ERR_BAD_ARG",
    -13: "J288_ERR_BAD_CONFIG",
    -14: "J288_ERR_PORT_OPS",
    -20: "J288_ERR_BAD_HEADER",
    -21: "J288_ERR_CRC",
    -22: "J288_ERR_TRUNCATED",
    -30: "J288_ERR_BUSY",
    -31: "J288_ERR_TIMEOUT",
    -32: "J288_ERR_WRONG_ID",
    -33: "J288_ERR_COLLISION",
    -34: "J288_ERR_LINE",
    -35: "J288_ERR_PORT",
    -36: "J288_ERR_TX_TIMEOUT",
    -37: "J288_ERR_ABORTED",
    -38: "J288_ERR_OVERFLOW",
    -39: "J288_ERR_OFFLINE",
    -50: "J288_ERR_ANGLE_UNKNOWN",
    -51: "J288_ERR_CAL_MISMATCH",
    -52: "J288_ERR_LIMIT_POS",
    -53: "J288_ERR_LIMIT_SPEED",
    -54: "J288_ERR_LIMIT_TORQUE",
    -55: "J288_ERR_CAL_DATA",
}


class J288Error(Exception):
    """A call into the library failed.

    Attributes:
        code: the library's result code (negative), e.g. -31.
        name: its name in j288/error.h, e.g. "J288_ERR_TIMEOUT".
        description: j288_strerror(code).
        detail: the runner's one-line message for errors it explains (device, config), or "".
    """

    def __init__(self, code: int, detail: str = "", what: str = "") -> None:
        self.code = code
        self.name = NAMES.get(code, f"J288_ERR_{-code}")
        self.description = LIB.j288_strerror(code).decode()
        self.detail = detail
        text = f"{self.name}: {self.description}"
        if what:
            text = f"{what}: {text}"
        if detail:
            text += f" ({detail})"
        super().__init__(text)


class OfflineError(J288Error):
    """J288_ERR_OFFLINE: the device is gone (adapter unplugged, simulator exited)."""


class BusLostError(OfflineError):
    """A bus was lost: it stopped answering, or its device vanished (J288_ERR_OFFLINE).
    Raised by Robot.cycle() (and run()) when it happened, unless the Robot was made with
    tolerate_bus_loss=True; the other buses went on (unless stop_on_bus_loss).

    Attributes:
        buses: the names of the buses lost.
        gone: of them, those whose device vanished (reopened when it reappears at its path).
        joints: the names of their joints: not known (read() says so) until they are back.
        cycle: the cycle's outcome (a Cycle; None from run()), to go on from.
    """

    def __init__(self, buses: List[str], gone: List[str], joints: List[str],
                 cycle: object = None, detail: str = "") -> None:
        self.buses = list(buses)
        self.gone = list(gone)
        self.joints = list(joints)
        self.cycle = cycle
        what = ", ".join(f"bus '{b}' lost ({'device vanished' if b in gone else 'no reply'})"
                         for b in buses)
        super().__init__(-39, detail, what)


class NoReplyError(J288Error):
    """J288_ERR_TIMEOUT: no reply in time (no servo with that id, or a bus not answering)."""


class WatchdogError(Exception):
    """A servo had tripped its 1 s watchdog (its host was silent): the host layer sent the
    command again with the watchdog bit 0, which cleared the trip, and the servo took it.
    Never a silent success: catch it to go on. .status is the reply (a ServoStatus)."""

    def __init__(self, status: object) -> None:
        self.status = status
        sid = getattr(status, "id", "?")
        super().__init__(f"servo {sid} had tripped its watchdog (no command for 1 s): cleared, "
                         "and the command sent again")


def error_for(code: int, detail: str = "", what: str = "") -> J288Error:
    """The exception for a result code."""
    if code == -39:
        return OfflineError(code, detail, what)
    if code == -31:
        return NoReplyError(code, detail, what)
    return J288Error(code, detail, what)
