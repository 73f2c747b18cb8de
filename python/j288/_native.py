"""The C library, loaded with ctypes: prototypes and the structures j288_robot.h declares.

Every structure below names the C type it mirrors (_c_type_); python/tests/test_layout.py
compiles a program that prints the C compiler's size, offsets and field kinds of each, and
fails on any difference, so that a field changed in C fails a test, not a robot.

ctypes is in the standard library: nothing to install and nothing to compile for the
binding itself, on every Python 3 Debian ships. cffi would need python3-cffi and a C compiler
at install time (API mode) or the same hand-written declarations (ABI mode), for no gain
here: the calls are few and coarse (one per cycle), so their per-call cost is what matters,
and it is measured in docs/performance.md.

The library is looked for, in order: $J288_LIB (a path), libj288.so next to this file (what
``make python`` puts there; j288.dll on Windows, libj288.dylib on macOS), the one of the
prefix ``make install`` put this package in (the path _installed.py holds, relative to this
directory, so that DESTDIR and a moved prefix work), then the system's (ldconfig's
libj288.so.0; on Windows a j288.dll on PATH).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import numbers
import os
import signal
import sys
import threading
from ctypes import (POINTER, Structure, c_bool, c_char_p, c_double, c_int, c_int32, c_size_t,
                    c_uint, c_uint8, c_uint16, c_uint32, c_void_p)
from typing import Optional, TypeVar

MAX_SERVOS = 15
BROADCAST_ID = 15


class Target(Structure):
    """j288_robot_target_t: joint frame (Robot) or output side (Bus), SI units."""

    _c_type_ = "j288_robot_target_t"
    _fields_ = [("pos", c_double), ("speed", c_double), ("torque", c_double),
                ("kp", c_double), ("kd", c_double)]


class ServoReply(Structure):
    """j288_robot_servo_t: one reply, output side."""

    _c_type_ = "j288_robot_servo_t"
    _fields_ = [("id", c_uint8), ("mode", c_uint8), ("watchdog_tripped", c_bool),
                ("pos", c_double), ("speed", c_double), ("torque", c_double),
                ("out_pos", c_double), ("case_temp_c", c_double),
                ("winding_temp_c", c_double), ("voltage_v", c_double),
                ("faults", c_uint32), ("warnings", c_uint8), ("latency_us", c_uint32),
                ("watchdog_cleared", c_bool), ("joint_known", c_bool), ("joint_pos", c_double),
                ("joint_speed", c_double), ("joint_torque", c_double)]


class JointState(Structure):
    """j288_robot_state_t: one joint, joint frame."""

    _c_type_ = "j288_robot_state_t"
    _fields_ = [("known", c_bool), ("online", c_bool), ("fresh", c_bool),
                ("pos", c_double), ("speed", c_double), ("torque", c_double),
                ("faults", c_uint32), ("warnings", c_uint8),
                ("case_temp_c", c_double), ("winding_temp_c", c_double),
                ("voltage_v", c_double)]


class CycleInfo(Structure):
    """j288_robot_cycle_t."""

    _c_type_ = "j288_robot_cycle_t"
    _fields_ = [("cycle", c_uint32), ("start_us", c_uint32), ("duration_us", c_uint32),
                ("fresh", c_uint), ("joints", c_uint), ("complete", c_bool),
                ("watchdog", c_uint), ("lost", c_uint), ("back", c_uint)]


class RobotStats(Structure):
    """j288_robot_stats_t."""

    _c_type_ = "j288_robot_stats_t"
    _fields_ = [("cycles", c_uint32), ("complete_cycles", c_uint32),
                ("last_cycle_us", c_uint32), ("worst_cycle_us", c_uint32),
                ("bus_losses", c_uint32), ("bus_returns", c_uint32)]


class BusStats(Structure):
    """j288_robot_bus_stats_t."""

    _c_type_ = "j288_robot_bus_stats_t"
    _fields_ = [("sweeps", c_uint32), ("empty_sweeps", c_uint32), ("down_events", c_uint32),
                ("last_sweep_us", c_uint32), ("worst_sweep_us", c_uint32),
                ("up", c_bool), ("gone", c_bool), ("gone_events", c_uint32),
                ("up_events", c_uint32), ("reopens", c_uint32), ("reopen_attempts", c_uint32),
                ("lost_at_us", c_uint32), ("back_at_us", c_uint32)]


class SlotStats(Structure):
    """j288_slot_stats_t (sched.h)."""

    _c_type_ = "j288_slot_stats_t"
    _fields_ = [(n, c_uint32) for n in (
        "transactions", "successes", "timeouts", "crc_errors", "wrong_id", "collisions",
        "other_errors", "consecutive_failures", "last_latency_us", "worst_latency_us")]


class JointStats(Structure):
    """j288_robot_joint_stats_t."""

    _c_type_ = "j288_robot_joint_stats_t"
    _fields_ = [("fresh_cycles", c_uint32), ("stale_cycles", c_uint32), ("servo", SlotStats)]


class Options(Structure):
    """j288_robot_options_t (callbacks left NULL: Python polls)."""

    _c_type_ = "j288_robot_options_t"
    _fields_ = [("port", c_char_p), ("baud", c_uint32), ("margin_us", c_uint32),
                ("down_after", c_uint8), ("no_low_latency", c_bool),
                ("on_event", c_void_p), ("on_cycle", c_void_p), ("user", c_void_p),
                ("stop_on_bus_loss", c_bool), ("echo", c_bool), ("retries", c_uint8),
                ("realtime", c_uint8), ("pin_cpu", c_bool), ("cpu", c_uint16),
                ("no_reopen", c_bool)]


class TimingSummary(Structure):
    """j288_rt_summary_t (host/j288_rt.h): one histogram's percentiles, microseconds."""

    _c_type_ = "j288_rt_summary_t"
    _fields_ = [(n, c_uint32) for n in ("count", "p50_us", "p99_us", "p999_us", "max_us")]


class TimingReport(Structure):
    """j288_rt_report_t: the loop's timing."""

    _c_type_ = "j288_rt_report_t"
    _fields_ = [("cycles", c_uint32), ("period_us", c_uint32), ("missed", c_uint32),
                ("skipped", c_uint32), ("cut", c_uint32), ("lateness", TimingSummary),
                ("duration", TimingSummary), ("priority", c_int32), ("cpu", c_int32),
                ("memory_locked", c_uint32)]


# The shared library's file name on each platform (Windows: what `make windows` builds).
_LIB_FILE = {"win32": "j288.dll", "cygwin": "j288.dll", "darwin": "libj288.dylib"}


def _find(platform: str = sys.platform, pkg: Optional[str] = None) -> str:
    env = os.environ.get("J288_LIB")
    if env:
        return env
    pkg = pkg or os.path.dirname(os.path.abspath(__file__))
    name = _LIB_FILE.get(platform, "libj288.so")
    here = os.path.join(pkg, name)
    if os.path.exists(here):
        return here
    try:  # written by `make install` only
        from ._installed import LIBRARY  # type: ignore[import-not-found,unused-ignore]
    except ImportError:
        LIBRARY = None
    if LIBRARY is not None and os.path.exists(os.path.join(pkg, LIBRARY)):
        return os.path.join(pkg, LIBRARY)
    found = ctypes.util.find_library("j288")
    if found:
        return found
    raise ImportError(f"{name} not found: run `make python` (in place) or `make install`, "
                      "or set J288_LIB to its path")


def _bind(lib: ctypes.CDLL) -> None:
    P = POINTER
    robot = c_void_p
    protos = {
        "j288_strerror": (c_char_p, [c_int]),
        "j288_robot_sizeof": (c_size_t, []),
        "j288_robot_version": (c_char_p, []),
        "j288_robot_open_file": (c_int, [robot, c_char_p, P(Options)]),
        "j288_robot_open_port": (c_int, [robot, c_char_p, P(Options)]),
        "j288_robot_close": (None, [robot]),
        "j288_robot_cycle": (c_int, [robot, c_uint32, P(CycleInfo)]),
        "j288_robot_run": (c_int, [robot, c_uint32, c_uint32, c_uint32]),
        "j288_robot_pace": (c_int, [robot, c_uint32]),
        "j288_robot_pace_restart": (None, [robot]),
        "j288_robot_timing": (c_int, [robot, c_void_p]),
        "j288_robot_timing_reset": (None, [robot]),
        "j288_robot_rt_notice": (c_char_p, [robot]),
        "j288_robot_stop": (c_int, [robot]),
        "j288_robot_njoints": (c_uint, [robot]),
        "j288_robot_nbuses": (c_uint, [robot]),
        "j288_robot_find_joint": (c_int, [robot, c_char_p]),
        "j288_robot_joint_name": (c_char_p, [robot, c_uint]),
        "j288_robot_bus_name": (c_char_p, [robot, c_uint]),
        "j288_robot_joint_bus": (c_int, [robot, c_uint]),
        "j288_robot_joint_id": (c_int, [robot, c_uint]),
        "j288_robot_read": (c_int, [robot, c_uint, P(JointState)]),
        "j288_robot_read_all": (c_int, [robot, c_size_t, P(c_double), P(c_double),
                                        P(c_double), P(c_uint8)]),
        "j288_robot_set_target": (c_int, [robot, c_uint, P(Target)]),
        "j288_robot_set_targets": (c_int, [robot, c_size_t, P(c_double), P(c_double),
                                           P(c_double), P(c_double), P(c_double), P(c_uint)]),
        "j288_robot_hold": (c_int, [robot, c_uint]),
        "j288_robot_lock": (c_int, [robot, c_uint]),
        "j288_robot_stats": (c_int, [robot, P(RobotStats)]),
        "j288_robot_bus_stats": (c_int, [robot, c_uint, P(BusStats)]),
        "j288_robot_joint_stats": (c_int, [robot, c_uint, P(JointStats)]),
        "j288_robot_exchange": (c_int, [robot, c_uint, c_uint8, P(Target), P(ServoReply)]),
        "j288_robot_exchange_joint": (c_int, [robot, c_uint, c_uint8, P(Target),
                                              P(ServoReply)]),
        "j288_robot_error": (c_char_p, [robot]),
    }
    for name, (res, args) in protos.items():
        fn = getattr(lib, name)
        fn.restype = res
        fn.argtypes = args


def _load() -> ctypes.CDLL:
    lib = ctypes.CDLL(_find())
    _bind(lib)
    return lib


LIB: ctypes.CDLL = _load()
VERSION: str = LIB.j288_robot_version().decode()


def new_robot() -> ctypes.Array:
    """Room for one j288_robot_t (the C side never allocates)."""
    return ctypes.create_string_buffer(LIB.j288_robot_sizeof())


def error_text(robot: Optional[ctypes.Array]) -> str:
    if robot is None:
        return ""
    return LIB.j288_robot_error(robot).decode(errors="replace")


_H = TypeVar("_H", bound="Handle")


class Terminated(SystemExit):
    """SIGTERM, SIGHUP (a closed terminal or SSH session) or SIGQUIT inside a Bus or Robot
    with block: the block's exit stopped the servos (broadcast lock, watchdog bit 0); the
    process then ends with status 128 + the signal's number (143, 129, 131), as the j288
    tool does. .signum: the signal."""

    def __init__(self, signum: int = signal.SIGTERM) -> None:
        self.signum = int(signum)
        super().__init__(128 + self.signum)


def _raise_on_signal(signum: int, frame: object) -> None:
    raise Terminated(signum)


# The signals whose default action would end the process with the servos still driven
# (Windows has only SIGTERM of them).
_STOP_SIGNALS = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGHUP", "SIGQUIT")
                      if hasattr(signal, n))


def path_arg(value: object, what: str) -> bytes:
    """A str or os.PathLike as bytes for the C side; TypeError otherwise."""
    if isinstance(value, (str, bytes, os.PathLike)):
        return os.fsencode(value)
    raise TypeError(f"{what} must be a path (str or os.PathLike), not {type(value).__name__}")


def int_arg(value: object, what: str, lo: int, hi: int) -> int:
    """An int in [lo, hi]; TypeError for another type (bool and float included), ValueError
    outside the range."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{what} must be an int, not {type(value).__name__} ({value!r})")
    if not lo <= int(value) <= hi:
        raise ValueError(f"{what} {value} outside {lo}-{hi}")
    return int(value)


def real_arg(value: object, what: str) -> float:
    """A real number (int or float, not bool) as float; TypeError otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what} must be a number, not {type(value).__name__} ({value!r})")
    return float(value)


class Handle:
    """What Bus and Robot share: one open j288_robot_t, stopped and closed once.

    Used as a context manager, the servos get the broadcast lock on exit (an exception or
    Ctrl-C included), then the handle closes; close() alone sends it only if something that
    moves a servo went out since the last stop.
    """

    _r: Optional[ctypes.Array] = None
    _kind = "handle"  # "bus" or "robot", for the closed-handle message

    def _open(self, rc: int, where: str) -> None:
        """Keep the handle if rc (of the open call on self._r) is 0, else raise."""
        if rc != 0:
            from .errors import error_for  # errors imports nothing of this module
            detail = error_text(self._r)
            self._r = None
            raise error_for(rc, detail, where)

    def _robot(self) -> ctypes.Array:
        if self._r is None:
            raise ValueError(f"the {self._kind} is closed")
        return self._r

    def close(self) -> None:
        """Stop (if a command went out since the last stop) and close. Safe twice."""
        if self._r is not None:
            LIB.j288_robot_close(self._r)
            self._r = None

    def __enter__(self: _H) -> _H:
        # SIGTERM, SIGHUP and SIGQUIT as Ctrl-C: an exception in the with block, so that
        # __exit__ stops the servos (their default actions would end the process with the
        # servos still driven). Only in the main thread, and only over the default action.
        self._old_handlers = {}
        if threading.current_thread() is threading.main_thread():
            for sig in _STOP_SIGNALS:
                if signal.getsignal(sig) == signal.SIG_DFL:
                    self._old_handlers[sig] = signal.signal(sig, _raise_on_signal)
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            if self._r is not None:
                LIB.j288_robot_stop(self._r)
        finally:
            self.close()
            for sig, old in getattr(self, "_old_handlers", {}).items():
                signal.signal(sig, old)
            self._old_handlers = {}

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may be gone already
            pass
