"""One bus, servo by servo: scan, status, command, lock, stop (joint frame by default, SI
units)."""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import List, Optional, Union
import os

from . import _native
from ._native import LIB, ServoReply, Target, int_arg, path_arg, real_arg
from .errors import J288Error, WatchdogError, error_for

MODE_LOCK = 0
MODE_FOC = 1

# Results that mean "no good reply from that id" (scan goes on to the next).
_BAD_REPLY = frozenset(("J288_ERR_TIMEOUT", "J288_ERR_CRC", "J288_ERR_TRUNCATED",
                        "J288_ERR_BAD_HEADER", "J288_ERR_WRONG_ID", "J288_ERR_COLLISION",
                        "J288_ERR_LINE"))


FRAMES = ("joint", "output")


@dataclass(frozen=True)
class ServoStatus:
    """One servo's reply, SI units, in the bus's frame: "joint" (the default), the absolute
    output angle wrapped to [-pi, pi) (the same number as `j288 status --id N --json`'s
    joint_pos); "output", the rotor's multi-turn count / 288.35, relative to where the rotor
    woke up."""

    id: int
    mode: int               #: 0 lock, 1 FOC
    pos: float              #: rad, in the bus's frame
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
    watchdog_cleared: bool = False  #: the servo had tripped; the command was re-sent to clear it

    @staticmethod
    def _from(r: ServoReply, joint: bool) -> "ServoStatus":
        pos, speed, torque = ((r.joint_pos, r.joint_speed, r.joint_torque) if joint
                              else (r.pos, r.speed, r.torque))
        return ServoStatus(r.id, r.mode, pos, speed, torque, r.out_pos, r.case_temp_c,
                           r.winding_temp_c, r.voltage_v, r.faults, r.warnings,
                           bool(r.watchdog_tripped), r.latency_us, bool(r.watchdog_cleared))


class Bus(_native.Handle):
    """A servo bus on a serial device (a USB adapter, or j288-sim's pseudo-terminal).

    Every frame of the protocol commands the servo: scan and status send lock (no torque,
    watchdog bit 0) to each id they probe. Positions are joint angles by default (frame
    "joint": the absolute output angle wrapped to [-pi, pi), as the j288 tool shows without
    a config; the first status or command of a servo takes a few lock exchanges to find it).
    Used as a context manager, the bus sends the broadcast lock on exit (an exception,
    Ctrl-C or SIGTERM included), then closes; close() alone sends it only if a command went
    out since the last stop::

        with j288.Bus("/dev/ttyUSB0", margin_us=3000) as bus:
            print(bus.scan())
            bus.command(2, pos=0.5, kp=20.0, kd=0.5)

    Args:
        port: the serial device (str or os.PathLike).
        baud: line rate in bit/s (default 6000000).
        margin_us: reply deadline margin for host latency (default 20 ms: USB adapters with
            the default latency timer; a pseudo-terminal or a 1 ms timer wants less).
        frame: "joint" (default) or "output" (rotor / 288.35, relative to power-up).
        retries: re-sends of a command that got no good reply, 0-3 (default 0, as `j288
            --retries`); each waits margin_us again, so an absent id costs a scan that many
            more margins.
    Raises:
        J288Error: the device cannot be opened (OfflineError: it does not exist), is in use
            by another program, or is not a serial device.
        TypeError, ValueError: an argument of the wrong type or outside its range.
    """

    _kind = "bus"

    def __init__(self, port: Union[str, "os.PathLike[str]"], baud: int = 0, margin_us: int = 0,
                 frame: str = "joint", retries: int = 0) -> None:
        dev = path_arg(port, "port")
        baud = int_arg(baud, "baud", 0, 100000000)
        margin_us = int_arg(margin_us, "margin_us", 0, 1000000)
        retries = int_arg(retries, "retries", 0, 3)
        if frame not in FRAMES:
            raise ValueError(f"frame {frame!r}: one of {', '.join(FRAMES)}")
        self._joint = frame == "joint"
        self._r: Optional[ctypes.Array] = _native.new_robot()
        opt = _native.Options(port=None, baud=baud, margin_us=margin_us, retries=retries)
        rc = LIB.j288_robot_open_port(self._r, dev, ctypes.byref(opt))
        self._open(rc, os.fsdecode(dev))
        self.port = os.fsdecode(dev)
        self.frame = frame

    def _exchange(self, servo_id: int, target: Optional[Target],
                  joint: Optional[bool] = None) -> ServoStatus:
        servo_id = int_arg(servo_id, "servo_id", 0, _native.MAX_SERVOS - 1)
        joint = self._joint if joint is None else joint
        reply = ServoReply()
        tp = ctypes.byref(target) if target is not None else None
        fn = LIB.j288_robot_exchange_joint if joint else LIB.j288_robot_exchange
        rc = fn(self._robot(), 0, servo_id, tp, ctypes.byref(reply))
        if rc != 0:
            raise error_for(rc, _native.error_text(self._r), f"servo {servo_id}")
        st = ServoStatus._from(reply, joint)
        if st.watchdog_cleared:
            raise WatchdogError(st)
        return st

    def scan(self, ids: Optional[List[int]] = None) -> List[int]:
        """The ids (0-14, or those of ids) that answer a lock command with a good reply, as
        `j288 scan` lists them: an id with no reply or a bad one (CRC, truncated, another
        id's, a collision) is left out. Raises OfflineError when the device is gone,
        J288Error (J288_ERR_BAD_ID) for an id outside 0-14."""
        found = []
        for i in (range(_native.MAX_SERVOS) if ids is None else ids):
            try:
                self._exchange(i, None, joint=False)
            except J288Error as e:
                if e.name in _BAD_REPLY:
                    continue
                raise
            found.append(i)
        return found

    def status(self, servo_id: int) -> ServoStatus:
        """Send lock to servo_id and return its reply. Raises NoReplyError when it is silent,
        J288Error J288_ERR_ANGLE_UNKNOWN (frame "joint") when its angle cannot be found."""
        return self._exchange(servo_id, None)

    def lock(self, servo_id: int) -> ServoStatus:
        """Put servo_id at lock (no torque); the same frame as status()."""
        return self._exchange(servo_id, None)

    def command(self, servo_id: int, pos: float = 0.0, speed: float = 0.0, torque: float = 0.0,
                kp: float = 0.0, kd: float = 0.0) -> ServoStatus:
        """One FOC command in the bus's frame: tau = torque + kp (pos - p) + kd (speed - v),
        with the servo's 1 s watchdog on. Returns the reply. Raises J288Error (e.g.
        J288_ERR_NEG_GAIN, J288_ERR_LIMIT_POS beyond [-pi, pi] in the joint frame with kp > 0:
        nothing was sent); WatchdogError when the servo had tripped its watchdog (no command for
        1 s): the command was sent again with the watchdog bit 0, which cleared the trip,
        and the servo took it (the exception's .status is the reply)."""
        t = Target(*(real_arg(v, n) for v, n in ((pos, "pos"), (speed, "speed"),
                                                   (torque, "torque"), (kp, "kp"), (kd, "kd"))))
        return self._exchange(servo_id, t)

    def stop(self) -> None:
        """Broadcast lock: every servo on the bus stops."""
        rc = LIB.j288_robot_stop(self._robot())
        if rc != 0:
            raise error_for(rc, _native.error_text(self._r), self.port)

