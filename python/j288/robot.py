"""A robot: every bus of a robot config file driven from one loop, joints in the joint frame."""

from __future__ import annotations

import ctypes
import os
import time
import warnings
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _native
from ._native import (LIB, BusStats, CycleInfo, JointState, JointStats, RobotStats, Target,
                      TimingReport, TimingSummary, c_double, c_uint, c_uint8, int_arg, path_arg,
                      real_arg)
from .errors import BusLostError, J288Error, error_for

try:  # NumPy is optional: arrays where a loop wants them, lists without it.
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None

Vector = Union[Sequence[float], Any]  # a sequence of floats or a NumPy array

_RUN_SLICE_US = 100000  # run(): Python's signal handlers get their turn this often
_REALTIME_DEFAULT = 80  # J288_RT_DEFAULT_PRIORITY
_MAX_SECONDS = 4000     # a cycle's timeout, run()'s period: microseconds in 32 bits


@dataclass(frozen=True)
class Cycle:
    """The outcome of one cycle (every bus swept once)."""

    number: int        #: cycles completed, this one included
    duration_us: int
    fresh: int         #: joints with a new reply in this cycle
    joints: int
    complete: bool     #: every joint fresh
    watchdog: int = 0  #: servos found with their watchdog tripped in this cycle (cleared by
    #: the host layer: their next command went out with the watchdog bit 0); never silent
    lost: Tuple[str, ...] = ()  #: buses lost since the previous cycle (stopped answering or
    #: vanished; cycle() raises BusLostError for them unless tolerate_bus_loss)
    back: Tuple[str, ...] = ()  #: buses back since then (answering again, or reopened: then
    #: their joints restart at lock and their angles are found again; set targets anew)


@dataclass(frozen=True)
class State:
    """One joint after the latest cycle: joint frame, SI units."""

    known: bool        #: pos is the absolute joint angle (after the first replies)
    online: bool
    fresh: bool        #: a reply came in the latest cycle
    pos: float         #: rad (0 while not known)
    speed: float       #: rad/s
    torque: float      #: N*m
    faults: int
    warnings: int
    case_temp_c: float
    winding_temp_c: float
    voltage_v: float


def _doubles(values: Optional[Vector], n: int) -> Tuple[Any, Any]:
    """(keep-alive object, double*) for n values, or (None, None)."""
    if values is None:
        return None, None
    if _np is not None:
        arr = _np.ascontiguousarray(values, dtype=_np.float64)
        if arr.shape != (n,):
            raise ValueError(f"expected {n} values, got shape {arr.shape}")
        return arr, arr.ctypes.data_as(ctypes.POINTER(c_double))
    vals = list(values)
    if len(vals) != n:
        raise ValueError(f"expected {n} values, got {len(vals)}")
    buf = (c_double * n)(*vals)
    return buf, ctypes.cast(buf, ctypes.POINTER(c_double))


class Robot(_native.Handle):
    """Every bus and joint of a robot config file (YAML: buses, joints with name, bus, id,
    direction, zero, limits or continuous: true (a wheel: no limits, the angle never wrapped),
    gains; every key commented in examples/robot.yaml).

    One cycle sends every joint its command on every bus at once and returns when each bus
    that answers has finished. Set targets between cycles::

        with j288.Robot("robot.yaml") as robot:
            while not all(robot.read()[3]):      # joint angles known after a few replies
                robot.cycle()
            robot.hold()
            for _ in range(1000):
                pos, speed, torque, known = robot.read()
                robot.set_targets(pos0 + 0.1)    # NumPy arrays, joint frame, rad
                robot.cycle()

    On exit from the with block (an exception, Ctrl-C, SIGTERM, SIGHUP or SIGQUIT included)
    every bus gets the broadcast lock (watchdog bit 0: the servos stay locked).

    A lost bus is never silent: cycle() (and run()) raises BusLostError when a bus stops
    answering or its device vanishes, naming the buses and their joints (the others go on;
    catch it to go on too, or make the Robot with tolerate_bus_loss=True and read Cycle.lost).
    Its joints read not known (read()[3], state().known) until they are back. A bus that
    stops answering is picked up again when it answers; a vanished device is opened again
    when it reappears at the same path (a udev symlink), its joints restarted at lock and
    their angles found again (Cycle.back names it; hold() or set targets anew once known).

    Args:
        config: path of the robot config file (str or os.PathLike).
        port: the device when the file names no bus.
        margin_us: reply margin for buses whose entry gives none (default 20 ms).
        down_after: sweeps without any reply before a bus is down and cycles stop waiting
            for it (default 3; until then a silent bus slows every cycle).
        stop_on_bus_loss: a bus that goes down or vanishes stops every bus and the cycle
            raises BusLostError (a legged robot is better all locked than half held).
        realtime: True (priority 80) or a SCHED_FIFO priority 1-99 for the thread that
            creates the Robot (the one that must run its loop: run(), pace(), cycle()), with
            the process's memory locked; close() undoes it. Without the rights a
            RuntimeWarning says how to get them (ulimit -r, /etc/security/limits.d,
            CAP_SYS_NICE) and the robot runs at normal priority (realtime_notice keeps the
            text). docs/realtime.md.
        cpu: pin that thread to this CPU (one the process may run on, else ValueError).
        tolerate_bus_loss: a lost bus raises nothing (Cycle.lost names it), and a cycle
            that finds every bus gone returns a Cycle with nothing fresh instead of raising
            OfflineError: for robots that ride out an unplugged adapter.
        reopen: open a vanished device again when it reappears (default True).
    Raises:
        J288Error: J288_ERR_BAD_CONFIG (file errors, with "FILE:LINE: ..." in detail), a
            device that cannot be opened (OfflineError), ...
    """

    _kind = "robot"

    def __init__(self, config: Union[str, "os.PathLike[str]"],
                 port: Union[str, "os.PathLike[str]", None] = None, margin_us: int = 0,
                 down_after: int = 0, stop_on_bus_loss: bool = False,
                 tolerate_bus_loss: bool = False, reopen: bool = True,
                 realtime: Union[bool, int] = False, cpu: Optional[int] = None) -> None:
        path = path_arg(config, "config")
        dev = path_arg(port, "port") if port is not None else None
        margin_us = int_arg(margin_us, "margin_us", 0, 1000000)
        down_after = int_arg(down_after, "down_after", 0, 255)
        if isinstance(realtime, bool):
            prio = _REALTIME_DEFAULT if realtime else 0
        else:
            prio = int_arg(realtime, "realtime", 1, 99)
        pin = cpu is not None
        cpu = int_arg(cpu, "cpu", 0, 1023) if pin else 0
        self._tolerate = bool(tolerate_bus_loss)
        self._stop_on_loss = bool(stop_on_bus_loss)
        self._r: Optional[ctypes.Array] = _native.new_robot()
        opt = _native.Options(port=dev, margin_us=margin_us, down_after=down_after,
                              stop_on_bus_loss=bool(stop_on_bus_loss), realtime=prio,
                              pin_cpu=pin, cpu=cpu, no_reopen=not reopen)
        rc = LIB.j288_robot_open_file(self._r, path, ctypes.byref(opt))
        self._open(rc, os.fsdecode(path))
        r = self._r
        #: what the real-time set-up refused and how to allow it ("" when nothing was)
        self.realtime_notice: str = LIB.j288_robot_rt_notice(r).decode(errors="replace")
        if self.realtime_notice:
            warnings.warn(self.realtime_notice.rstrip("\n"), RuntimeWarning, stacklevel=2)
        self.joints: List[str] = [LIB.j288_robot_joint_name(r, j).decode()
                                  for j in range(LIB.j288_robot_njoints(r))]
        self.buses: List[str] = [LIB.j288_robot_bus_name(r, b).decode()
                                 for b in range(LIB.j288_robot_nbuses(r))]
        self._n = len(self.joints)
        self._pos = (c_double * self._n)()
        self._speed = (c_double * self._n)()
        self._torque = (c_double * self._n)()
        self._known = (c_uint8 * self._n)()
        # Each bus's (down, gone, back) counts so far: which buses a cycle's counts are about.
        self._seen: List[Tuple[int, int, int]] = [(0, 0, 0)] * len(self.buses)
        self._run_losses = 0

    # ---- plumbing
    def _check(self, rc: int, what: str = "") -> None:
        if rc != 0:
            raise error_for(rc, _native.error_text(self._r), what)

    def _index(self, joint: Union[int, str]) -> int:
        if isinstance(joint, str):
            j = LIB.j288_robot_find_joint(self._robot(), joint.encode())
            if j < 0:
                raise KeyError(f"no joint named {joint!r}")
            return int(j)
        try:
            return int_arg(joint, "joint", 0, self._n - 1)
        except ValueError:
            raise IndexError(f"joint index {joint} outside 0-{self._n - 1}") from None

    # ---- the loop
    def _bus_changes(self) -> Tuple[List[str], List[str], List[str]]:
        """(lost, gone, back): the buses lost, of them those whose device vanished, and the
        buses back, since the previous call (from each bus's counters)."""
        lost, gone, back = [], [], []
        s = BusStats()
        for b, name in enumerate(self.buses):
            self._check(LIB.j288_robot_bus_stats(self._robot(), b, ctypes.byref(s)))
            seen = (s.down_events, s.gone_events, s.up_events + s.reopens)
            if seen[0] + seen[1] != sum(self._seen[b][:2]):
                lost.append(name)
            if seen[1] != self._seen[b][1]:
                gone.append(name)
            if seen[2] != self._seen[b][2]:
                back.append(name)
            self._seen[b] = seen
        return lost, gone, back

    def _lost_error(self, lost: List[str], gone: List[str], cycle: Optional[Cycle]) -> BusLostError:
        joints = [self.joints[j] for j in range(self._n)
                  if self.buses[LIB.j288_robot_joint_bus(self._robot(), j)] in lost]
        return BusLostError(lost, gone, joints, cycle, _native.error_text(self._r))

    def cycle(self, timeout: float = 1.0) -> Cycle:
        """Sweep every bus once. Returns the cycle's outcome, also when some joint got no
        reply (complete False; watchdog > 0: servos found tripped, cleared; back: buses back).
        timeout: seconds, (0, 4000]. Raises BusLostError when a bus was lost since the
        previous cycle (unless tolerate_bus_loss; with stop_on_bus_loss every bus was
        stopped), OfflineError when every bus is gone (unless tolerate_bus_loss: then a
        Cycle with nothing fresh, after waiting for the next reopen attempt)."""
        timeout = real_arg(timeout, "timeout")
        if not 0 < timeout <= _MAX_SECONDS:
            raise ValueError(f"timeout {timeout} s outside (0, {_MAX_SECONDS}]")
        info = CycleInfo()
        rc = LIB.j288_robot_cycle(self._robot(), int(timeout * 1e6), ctypes.byref(info))
        lost: List[str] = []
        gone: List[str] = []
        back: List[str] = []
        if info.lost or info.back or rc == -39:
            lost, gone, back = self._bus_changes()
        c = Cycle(info.cycle, info.duration_us, info.fresh, self._n, bool(info.complete),
                  info.watchdog, tuple(lost), tuple(back))
        stopped = rc == -39 and self._stop_on_loss  # the runner stopped every bus
        if lost and (not self._tolerate or stopped):
            raise self._lost_error(lost, gone, c)
        if rc == -39 and self._tolerate and not stopped:
            return c  # every bus gone: nothing fresh, nothing raised
        if rc not in (0, -31):
            self._check(rc)
        return c

    def run(self, cycles: int = 0, rate_hz: float = 0.0, duration: float = 0.0) -> None:
        """Cycles in C (no Python per cycle): `cycles` of them (0: no limit) or for `duration`
        seconds (0: no limit), at rate_hz (0: back to back), with the targets set before.

        The C loop runs in slices of about 0.1 s on one schedule of absolute deadlines (each
        slice takes it up where the last left it: the rate holds): Ctrl-C (KeyboardInterrupt)
        and other signals reach Python between them, and a with block around the loop then
        stops every bus. A call starts a new schedule. A missed deadline is skipped, never
        caught up (see pace()). Raises BusLostError at the end of the slice in which a bus was
        lost (unless tolerate_bus_loss: then a run rides out even every bus gone, waiting for
        the devices to come back)."""
        if not (0 <= cycles < 2**32 and (rate_hz == 0 or 1 / _MAX_SECONDS <= rate_hz)
                and duration >= 0):
            raise ValueError(f"cycles 0 to 2**32 - 1, rate_hz 0 or from {1 / _MAX_SECONDS}, "
                             "duration >= 0")
        r = self._robot()
        period = int(1e6 / rate_hz) if rate_hz > 0 else 0
        slice_us = period * max(1, _RUN_SLICE_US // period) if period else _RUN_SLICE_US
        left_us = int(duration * 1e6) if duration > 0 else None
        left = cycles
        stats = RobotStats()
        LIB.j288_robot_pace_restart(r)
        while left_us is None or left_us > 0:
            this_us = slice_us if left_us is None else min(slice_us, left_us)
            self._check(LIB.j288_robot_stats(r, ctypes.byref(stats)))
            before = stats.cycles
            start = time.monotonic()
            rc = LIB.j288_robot_run(r, period, left, this_us)
            self._check(LIB.j288_robot_stats(r, ctypes.byref(stats)))
            if stats.bus_losses != self._run_losses or rc == -39:
                self._run_losses = stats.bus_losses
                lost, gone, _ = self._bus_changes()
                if lost and (not self._tolerate or rc == -39):
                    raise self._lost_error(lost, gone, None)
            self._check(rc)
            if left_us is not None:
                left_us -= max(this_us, int((time.monotonic() - start) * 1e6))
            if cycles:
                self._check(LIB.j288_robot_stats(r, ctypes.byref(stats)))
                left -= min(left, (stats.cycles - before) & 0xFFFFFFFF)
                if left == 0:
                    return

    def pace(self, rate_hz: float) -> None:
        """Wait for the next cycle's deadline, for a loop of your own::

            while running:
                robot.pace(500)          # deadlines 2 ms apart, absolute
                pos, *_ = robot.read()
                robot.set_targets(...)
                robot.cycle()

        Cycle k is due at the first call's time + k / rate_hz (the first call, or the
        first at another rate, starts the schedule and returns at once). The buses are
        served meanwhile. A deadline already past when it is called (the loop overran) is
        missed: it returns at once, and whole periods behind are skipped, never run back to
        back. Each call ends a cycle: its duration, the wake-up's lateness, misses and
        skips go into stats()["timing"]. Raises OfflineError when every bus is gone and
        reopen is False (with reconnection the next cycle() waits for a device instead)."""
        rate_hz = real_arg(rate_hz, "rate_hz")
        if not 1 / _MAX_SECONDS <= rate_hz <= 1e6:
            raise ValueError(f"rate_hz {rate_hz} outside [{1 / _MAX_SECONDS}, 1e6]")
        self._check(LIB.j288_robot_pace(self._robot(), int(round(1e6 / rate_hz))))

    def stop(self) -> None:
        """Broadcast lock on every bus; every joint at lock until new targets are set."""
        self._check(LIB.j288_robot_stop(self._robot()))

    # ---- state
    def read(self) -> Tuple[Any, Any, Any, Any]:
        """(pos, speed, torque, known) of every joint, in self.joints' order: NumPy arrays
        (float64, bool) when NumPy is there, else lists. Joint frame, rad, rad/s, N*m."""
        self._check(LIB.j288_robot_read_all(self._robot(), self._n, self._pos, self._speed,
                                            self._torque, self._known))
        if _np is not None:
            return (_np.frombuffer(self._pos, dtype=_np.float64).copy(),
                    _np.frombuffer(self._speed, dtype=_np.float64).copy(),
                    _np.frombuffer(self._torque, dtype=_np.float64).copy(),
                    _np.frombuffer(self._known, dtype=_np.uint8).astype(bool))
        return (list(self._pos), list(self._speed), list(self._torque),
                [bool(k) for k in self._known])

    def state(self, joint: Union[int, str]) -> State:
        """One joint's state (by name or index)."""
        st = JointState()
        self._check(LIB.j288_robot_read(self._robot(), self._index(joint), ctypes.byref(st)))
        return State(bool(st.known), bool(st.online), bool(st.fresh), st.pos, st.speed,
                     st.torque, st.faults, st.warnings, st.case_temp_c, st.winding_temp_c,
                     st.voltage_v)

    # ---- targets (sent in the next cycle)
    def set_target(self, joint: Union[int, str], pos: float, speed: float = 0.0,
                   torque: float = 0.0, kp: float = 0.0, kd: float = 0.0) -> None:
        """One joint's target, joint frame. Raises J288Error: J288_ERR_ANGLE_UNKNOWN (not
        known yet), J288_ERR_LIMIT_POS / _SPEED / _TORQUE (outside its limits), ..."""
        j = self._index(joint)
        t = Target(*(real_arg(v, n) for v, n in ((pos, "pos"), (speed, "speed"),
                                                   (torque, "torque"), (kp, "kp"), (kd, "kd"))))
        self._check(LIB.j288_robot_set_target(self._robot(), j, ctypes.byref(t)),
                    self.joints[j])

    def set_targets(self, pos: Vector, speed: Optional[Vector] = None,
                    torque: Optional[Vector] = None, kp: Optional[Vector] = None,
                    kd: Optional[Vector] = None) -> None:
        """Every joint's target at once (arrays in self.joints' order; gains default to
        each joint's configured kp, kd). All are checked first: on an error none changes,
        and the exception names the joint."""
        n = self._n
        keep = [_doubles(v, n) for v in (pos, speed, torque, kp, kd)]
        bad = c_uint(0)
        rc = LIB.j288_robot_set_targets(self._robot(), n, *[p for _, p in keep],
                                        ctypes.byref(bad))
        if rc != 0:
            name = self.joints[bad.value] if bad.value < n else ""
            self._check(rc, name)

    def hold(self, joint: Union[int, str, None] = None) -> None:
        """Hold a joint (or every joint) where it is, with its configured gains."""
        for j in ([self._index(joint)] if joint is not None else range(self._n)):
            self._check(LIB.j288_robot_hold(self._robot(), j), self.joints[j])

    def lock(self, joint: Union[int, str, None] = None) -> None:
        """Put a joint (or every joint) at lock (no torque) from the next cycle."""
        for j in ([self._index(joint)] if joint is not None else range(self._n)):
            self._check(LIB.j288_robot_lock(self._robot(), j), self.joints[j])

    # ---- statistics
    def stats(self) -> Dict[str, Any]:
        """Cycles, complete cycles, last and worst cycle time (us), and "timing": the loop's
        timing as `j288 log --json` gives it: cycles (ended by a paced wait), period_us,
        missed_deadlines, skipped_periods, cut_cycles (ended by their timeout),
        lateness_us and duration_us (each count, p50, p99, p99_9, max: wake-up lateness at
        each deadline, and each cycle's duration to the next wait), priority (SCHED_FIFO,
        0: normal), cpu (-1: not pinned), memory_locked."""
        s = RobotStats()
        r = self._robot()
        self._check(LIB.j288_robot_stats(r, ctypes.byref(s)))
        out: Dict[str, Any] = {f: getattr(s, f) for f, _ in RobotStats._fields_}
        t = TimingReport()
        self._check(LIB.j288_robot_timing(r, ctypes.byref(t)))

        def summary(h: TimingSummary) -> Dict[str, int]:
            return {"count": h.count, "p50": h.p50_us, "p99": h.p99_us, "p99_9": h.p999_us,
                    "max": h.max_us}
        out["timing"] = {"cycles": t.cycles, "period_us": t.period_us,
                         "missed_deadlines": t.missed, "skipped_periods": t.skipped,
                         "cut_cycles": t.cut, "lateness_us": summary(t.lateness),
                         "duration_us": summary(t.duration), "priority": t.priority,
                         "cpu": t.cpu, "memory_locked": bool(t.memory_locked)}
        return out

    def reset_timing(self) -> None:
        """Start the timing statistics (stats()["timing"]) afresh, e.g. after start-up."""
        LIB.j288_robot_timing_reset(self._robot())

    def bus_stats(self, bus: Union[int, str]) -> Dict[str, Any]:
        """One bus: sweeps, empty sweeps, down events, sweep times, up, gone."""
        b = self.buses.index(bus) if isinstance(bus, str) else bus
        s = BusStats()
        self._check(LIB.j288_robot_bus_stats(self._robot(), b, ctypes.byref(s)))
        return {f: getattr(s, f) for f, _ in BusStats._fields_}

    def joint_stats(self, joint: Union[int, str]) -> Dict[str, int]:
        """One joint: fresh and stale cycles, and its servo's transaction counters."""
        s = JointStats()
        self._check(LIB.j288_robot_joint_stats(self._robot(), self._index(joint),
                                               ctypes.byref(s)))
        out = {"fresh_cycles": s.fresh_cycles, "stale_cycles": s.stale_cycles}
        out.update({f: getattr(s.servo, f) for f, _ in s.servo._fields_})
        return out


__all__ = ["Robot", "Cycle", "State", "J288Error"]
