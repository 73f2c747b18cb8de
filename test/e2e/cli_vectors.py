#!/usr/bin/env python3
"""Check `j288 encode` and `j288 decode --json` against the golden vectors.

Usage: cli_vectors.py J288_BINARY VECTOR_DIR

The vectors come from the independent generator (tools/vectors/gen_vectors.py):
- commands.txt: decoding each frame gives its fields; fields an encoder accepts encode to
  exactly the frame; fields it refuses make `encode` fail cleanly (exit 2, one stderr line,
  nothing on stdout).
- replies.txt: decoding each frame gives its fields, voltage in volts and one fault name per
  set bit.
- si_commands.txt: the SI options with --side give exactly the frame, or fail cleanly.
Prints one line per failure and a count; exits 1 on any failure.
"""
import json
import os
import subprocess
import sys


def run(binary, args):
    p = subprocess.run([binary] + args, capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


# J288_E2E_VECTOR_STRIDE=N checks every N-th vector of each file only (make test-valgrind, 20,
# and test-asan, 4: each run of the tool there costs a fraction of a second).
STRIDE = max(1, int(os.environ.get("J288_E2E_VECTOR_STRIDE", "1")))


def vectors(path):
    n = 0
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                if n % STRIDE == 0:
                    yield line.split()
                n += 1


class Checker:
    def __init__(self, binary):
        self.binary = binary
        self.checks = 0
        self.failures = []

    def fail(self, name, why):
        self.failures.append(f"{name}: {why}")

    def expect_encode(self, name, args, want_hex):
        self.checks += 1
        rc, out, err = run(self.binary, ["encode"] + args)
        if rc != 0 or out != want_hex + "\n" or err:
            self.fail(name, f"encode {' '.join(args)} -> rc {rc} out {out!r} err {err!r}, "
                      f"want {want_hex}")

    def expect_encode_refused(self, name, args):
        self.checks += 1
        rc, out, err = run(self.binary, ["encode"] + args)
        if rc != 2 or out or err.count("\n") != 1:
            self.fail(name, f"encode {' '.join(args)} should be refused: rc {rc} out {out!r} "
                      f"err {err!r}")

    def expect_decode(self, name, hexstr, want):
        self.checks += 1
        rc, out, err = run(self.binary, ["decode", "--json", hexstr])
        if rc != 0 or err:
            self.fail(name, f"decode rc {rc} err {err!r}")
            return None
        try:
            obj = json.loads(out)
        except ValueError as e:
            self.fail(name, f"decode --json is not JSON ({e}): {out!r}")
            return None
        bad = {k: (obj.get(k), v) for k, v in want.items() if obj.get(k) != v}
        if bad:
            self.fail(name, f"decode fields (got, want): {bad}")
        return obj


MODES = {0: "lock", 1: "foc"}


def check_commands(c, path):
    n = 0
    for v in vectors(path):
        name, id_, status, wd, tau, speed, pos, kp, kd, reserved, expect, hexstr = v
        ints = [int(x) for x in (id_, status, wd, tau, speed, pos, kp, kd, reserved)]
        id_, status, wd, tau, speed, pos, kp, kd, reserved = ints
        n += 1
        c.expect_decode(name, hexstr, dict(frame="command", id=id_, mode=status, watchdog=wd,
                                            tau_raw=tau, speed_raw=speed, pos_raw=pos,
                                            kp_raw=kp, kd_raw=kd, reserved=reserved))
        if status not in MODES:
            continue  # the CLI offers lock and foc only: nothing to encode
        args = ["--id", str(id_), "--mode", MODES[status], "--watchdog", "on" if wd else "off",
                "--tau-raw", str(tau), "--speed-raw", str(speed), "--pos-raw", str(pos),
                "--kp-raw", str(kp), "--kd-raw", str(kd)]
        if expect == "ok":
            c.expect_encode(name, args, hexstr)
        elif expect.startswith("J288_ERR"):
            c.expect_encode_refused(name, args)
    return n


def check_replies(c, path):
    n = 0
    for v in vectors(path):
        (name, id_, status, wd, case_t, wind_t, volt, torque, speed, pos, faults, out_pos,
         warnings, reserved, expect, hexstr) = v
        n += 1
        faults = int(faults, 16)
        want = dict(frame="reply", id=int(id_), mode=int(status), watchdog=int(wd),
                    case_temp_c=int(case_t), winding_temp_c=int(wind_t),
                    voltage_raw=int(volt), torque_raw=int(torque), speed_raw=int(speed),
                    pos_raw=int(pos), faults=faults, out_pos_raw=int(out_pos),
                    warnings=int(warnings), reserved=int(reserved))
        obj = c.expect_decode(name, hexstr, want)
        if obj is None:
            continue
        c.checks += 1
        if obj.get("voltage_v") != int(volt) * 0.5:
            c.fail(name, f"voltage_v {obj.get('voltage_v')}, want {int(volt) * 0.5}")
        names = obj.get("fault_names")
        if not isinstance(names, list) or len(names) != bin(faults).count("1") or \
                not all(isinstance(s, str) and s for s in names):
            c.fail(name, f"fault_names {names!r} for faults {faults:#x}")
    return n


def check_si_commands(c, path):
    n = 0
    for v in vectors(path):
        name, side, id_, status, wd, tau, speed, pos, kp, kd, expect, hexstr = v[:12]
        if int(status) not in MODES:
            continue
        n += 1
        args = ["--id", id_, "--mode", MODES[int(status)], "--watchdog",
                "on" if int(wd) else "off", "--side", side, "--tau", tau, "--speed", speed,
                "--pos", pos, "--kp", kp, "--kd", kd]
        if expect == "ok":
            c.expect_encode(name, args, hexstr)
        else:
            c.expect_encode_refused(name, args)
    return n


def main():
    binary, vdir = sys.argv[1], sys.argv[2]
    c = Checker(binary)
    counts = {}
    for fname, fn in (("commands.txt", check_commands), ("replies.txt", check_replies),
                      ("si_commands.txt", check_si_commands)):
        path = os.path.join(vdir, fname)
        if os.path.exists(path):
            counts[fname] = fn(c, path)
    least = 300 // STRIDE
    if counts.get("commands.txt", 0) < least or counts.get("replies.txt", 0) < least:
        c.fail("vectors", f"too few vectors found: {counts}")
    for f in c.failures[:40]:
        print("FAIL", f)
    print(f"golden vectors: {counts}, {c.checks} checks, {len(c.failures)} failures")
    sys.exit(1 if c.failures else 0)


if __name__ == "__main__":
    main()
