"""One bus, servo by servo: scan, status, command, lock, stop (output side, SI units)."""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import List, Optional

from . import _native
from ._native import LIB, ServoReply, Target
from .errors import J288Error, error_for

MODE_LOCK = 0
MODE_FOC = 1

# Results that mean "no good reply from that id" (scan goes on to the next).
_BAD_REPLY = frozenset(("J288_ERR_TIMEOUT", "J288_ERR_CRC", "J288_ERR_TRUNCATED",
                        "J288_ERR_BAD_HEADER", "J288_ERR_WRONG_ID", "J288_ERR_COLLISION",
                        "J288_ERR_LINE"))


@dataclass(frozen=True)
class ServoStatus:
    """One servo's reply, output side (after the 288.35:1 gear), SI units."""

    id: int
    mode: int               #: 0 lock, 1 FOC
    pos: float              #: rad, from the rotor's multi-turn count (relative after power-up)
    speed: float            #: rad/s
    torque: float           #: N*m
    out_pos: float          #: rad, the output encoder, [0, 2 pi), absolute over one turn
    case_temp_c: float
    winding_temp_c: float
    voltage_v: float
    faults: int             #: J288_FAULT_* bits (0: none)
    warnings: int
    watchdog_tripped: bool
    latency_us: int

    @staticmethod
    def _from(r: ServoReply) -> "ServoStatus":
        return ServoStatus(r.id, r.mode, r.pos, r.speed, r.torque, r.out_pos, r.case_temp_c,
                           r.winding_temp_c, r.voltage_v, r.faults, r.warnings,
                           bool(r.watchdog_tripped), r.latency_us)


class Bus(_native.Handle):
    """A servo bus on a serial device (a USB adapter, or j288-sim's pseudo-terminal).

    Every frame of the protocol commands the servo: scan and status send lock (no torque) to
    each id they probe. Used as a context manager, the bus sends the broadcast lock on exit
    (an exception or Ctrl-C included), then closes; close() alone sends it only if a command
    went out since the last stop::

        with j288.Bus("/dev/ttyUSB0", margin_us=3000) as bus:
            print(bus.scan())
            bus.command(2, pos=0.5, kp=20.0, kd=0.5)

    Args:
        port: the serial device.
        baud: line rate in bit/s (default 6000000).
        margin_us: reply deadline margin for host latency (default 20 ms: USB adapters with
            the default latency timer; a pseudo-terminal or a 1 ms timer wants less).
    Raises:
        J288Error: the device cannot be opened (OfflineError: it does not exist), is in use
            by another program, or is not a serial device.
    """

    _kind = "bus"

    def __init__(self, port: str, baud: int = 0, margin_us: int = 0) -> None:
        self._r: Optional[ctypes.Array] = _native.new_robot()
        opt = _native.Options(port=None, baud=baud, margin_us=margin_us)
        rc = LIB.j288_robot_open_port(self._r, port.encode(), ctypes.byref(opt))
        self._open(rc, port)
        self.port = port

    def _exchange(self, servo_id: int, target: Optional[Target]) -> ServoStatus:
        reply = ServoReply()
        tp = ctypes.byref(target) if target is not None else None
        rc = LIB.j288_robot_exchange(self._robot(), 0, servo_id, tp, ctypes.byref(reply))
        if rc != 0:
            raise error_for(rc, _native.error_text(self._r), f"servo {servo_id}")
        return ServoStatus._from(reply)

    def scan(self, ids: Optional[List[int]] = None) -> List[int]:
        """The ids (0-14, or those of ids) that answer a lock command with a good reply, as
        `j288 scan` lists them: an id with no reply or a bad one (CRC, truncated, another
        id's, a collision) is left out. Raises OfflineError when the device is gone,
        J288Error (J288_ERR_BAD_ID) for an id outside 0-14."""
        found = []
        for i in (range(_native.MAX_SERVOS) if ids is None else ids):
            try:
                self._exchange(i, None)
            except J288Error as e:
                if e.name in _BAD_REPLY:
                    continue
                raise
            found.append(i)
        return found

    def status(self, servo_id: int) -> ServoStatus:
        """Send lock to servo_id and return its reply. Raises NoReplyError when it is silent."""
        return self._exchange(servo_id, None)

    def lock(self, servo_id: int) -> ServoStatus:
        """Put servo_id at lock (no torque); the same frame as status()."""
        return self._exchange(servo_id, None)

    def command(self, servo_id: int, pos: float = 0.0, speed: float = 0.0, torque: float = 0.0,
                kp: float = 0.0, kd: float = 0.0) -> ServoStatus:
        """One FOC command, output side: tau = torque + kp (pos - p) + kd (speed - v), with
        the servo's 1 s watchdog on. Returns the reply. Raises J288Error (e.g.
        J288_ERR_NEG_GAIN, J288_ERR_RANGE_POS: nothing was sent)."""
        return self._exchange(servo_id, Target(pos, speed, torque, kp, kd))

    def stop(self) -> None:
        """Broadcast lock: every servo on the bus stops."""
        rc = LIB.j288_robot_stop(self._robot())
        if rc != 0:
            raise error_for(rc, _native.error_text(self._r), self.port)

