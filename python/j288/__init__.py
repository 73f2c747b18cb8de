"""j288: Unitree J288/S288 servo buses from Python, over the C library (libj288.so).

    import j288
    print(sorted(j288.Bus("/dev/ttyUSB0").scan()))     # ids that answer, e.g. [2, 7]
    with j288.Robot("robot.yaml") as robot:            # every bus of a robot config
        robot.cycle()

Bus: one bus, servo by servo (joint frame by default, SI units). Robot: every bus and joint of a robot
config file in one loop (joint frame). Errors raise J288Error, whose .name is the library's
(e.g. "J288_ERR_TIMEOUT"). Both are context managers that stop the servos on exit.
"""

from ._native import VERSION as __version__
from .bus import MODE_FOC, MODE_LOCK, Bus, ServoStatus
from ._native import Terminated
from .errors import BusLostError, J288Error, NoReplyError, OfflineError, WatchdogError
from .robot import Cycle, Robot, State

__all__ = ["Bus", "Robot", "ServoStatus", "Cycle", "State", "J288Error", "NoReplyError",
           "OfflineError", "BusLostError", "WatchdogError", "Terminated", "MODE_LOCK", "MODE_FOC",
           "__version__"]
