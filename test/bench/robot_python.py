"""Python's cost per cycle against the C loop (scripts/bench-robot.sh).

usage: PYTHONPATH=python python3 test/bench/robot_python.py CONFIG SECONDS

The same robot, the same simulators: cycles/s of the C loop (Robot.run: no Python per
cycle) against a Python loop that does what a controller does each cycle (cycle(), read()
of every joint, set_targets() of every joint), and the CPU time of those Python calls alone
(no bus wait: per_call measures read() + set_targets() + the ctypes entry of cycle()).
"""

import sys
import time

import j288


def main() -> None:
    config, seconds = sys.argv[1], float(sys.argv[2])
    with j288.Robot(config) as robot:
        while not all(robot.read()[3]):
            robot.cycle()
        robot.hold()
        pos0 = robot.read()[0]

        s0 = robot.stats()["cycles"]
        t0 = time.perf_counter()
        robot.run(duration=seconds)
        c_rate = (robot.stats()["cycles"] - s0) / (time.perf_counter() - t0)

        n = 0
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            robot.cycle()
            pos, speed, torque, known = robot.read()
            robot.set_targets(pos0)
            n += 1
        py_rate = n / (time.perf_counter() - t0)

        reps = 20000
        t0 = time.process_time()
        for _ in range(reps):
            pos, speed, torque, known = robot.read()
            robot.set_targets(pos0)
        per_call_us = (time.process_time() - t0) / reps * 1e6
    numpy = "with NumPy" if j288.robot._np is not None else "without NumPy"
    print(f"python {sys.version.split()[0]} {numpy}, {len(robot.joints)} joints")
    print(f"{'C loop (Robot.run)':28s} {c_rate:10.0f} cycles/s  {1e6 / c_rate:7.1f} us/cycle")
    print(f"{'Python loop':28s} {py_rate:10.0f} cycles/s  {1e6 / py_rate:7.1f} us/cycle")
    print(f"{'Python per cycle, CPU':28s} {per_call_us:10.1f} us (read + set_targets, 12 joints)")


if __name__ == "__main__":
    main()
