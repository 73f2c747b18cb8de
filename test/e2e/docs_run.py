#!/usr/bin/env python3
"""Run every command the docs show against j288-sim, so that the docs cannot drift.

usage: docs_run.py [-v] --dev LINK --log SIMLOG --bin BIN --work DIR FILE.md...

Prints docs_run:FILE:LINE:PASS or FAIL per command run (test/e2e/docs_run.sh, which starts a
simulator and writes DIR/robot.yaml for each group of files, counts them); exits 1 on a
failure. The convention it checks is written down in docs/architecture.md ("Commands in the
docs"):

What runs. A command is a line of a fenced code block (after an optional "$ " prompt; "#"
comments and "\\" continuations as in sh) or an inline `code span` whose program is j288 or
j288-sim (bare, or as build/bin/...; leading VAR=value assignments allowed). Every other
program (make, sudo, cmake, python3, j288.exe, j288-dds, ...) is not run here. Not run either,
and listed: syntax with placeholders (an all-capitals word such as FILE, DEV or N, or [ ] | ...
<), an error message quoted in a span ("j288 zero: ..."), and a span that only names a command
("`j288 scan`": no option).

How. Each runs in DIR (a scratch folder, with build/bin there linking to BIN), the program
being the build's. Every serial device the docs use (/dev/ttyUSB0, /dev/ttyUSB1, /dev/j288,
build/demo/bus, /tmp/j288bus, /tmp/bus) is LINK, the simulator (servos 0-14; hip and knee in
DIR/robot.yaml are 1 and 2), and so is $J288_PORT; a j288-sim command gets a link of its own.
A j288 bus command that gives no --margin-us gets --margin-us 1000000 before it: on a loaded
machine the pseudo-terminal's default 5 ms misses replies (make demo, whose output is checked
as it prints it, is run once more when it failed). A command that runs
until Ctrl-C (hold, move, torque without --duration or --arrive; the robot form's hold; a
j288-sim) is interrupted once it is driving (the simulator logs its first FOC command; a
j288-sim: its link exists), and must then exit 130 (0 for j288-sim). Any other must exit 0
(jog: exit 2 saying it needs a terminal, its options all taken: test/e2e/cli_jog.sh runs it
on one). Under "$ " prompts, the lines that follow a command are its output: each must match
a line of what the command printed (stdout and stderr), in order; digits stand for any number,
runs of blanks for any blanks, a line ending in "..." for any ending, a line "..." for lines
left out.

Markers (HTML comments, invisible when rendered):
  <!-- docs-run: skip REASON -->           on the line before a fenced block: not run
  <!-- docs-run: skip "TEXT" REASON -->    anywhere: no command containing TEXT is run
  <!-- docs-run: output of make demo -->   before a block: the block is `make demo`'s output
Every command not run is listed with the reason (-v lists every command).
"""
import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time

PROGRAMS = {"j288", "j288-sim"}
COMMANDS = {"encode", "decode", "scan", "status", "hold", "move", "torque", "stop", "log", "plot",
            "zero", "calibrate", "top", "jog", "help"}
DEVICES = ["/dev/ttyUSB0", "/dev/ttyUSB1", "/dev/j288", "build/demo/bus", "/tmp/j288bus", "/tmp/bus"]
TIME_SCALE = int(os.environ.get("TEST_TIME_SCALE", "1") or "1")
BOUND = 60 * TIME_SCALE  # seconds any one command may take (a hang fails, not a time)
MARKER = re.compile(r"<!--\s*docs-run:\s*(.*?)\s*-->")
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*(\.[a-z0-9]+)?$")


class Item:
    def __init__(self, path, line, text, kind, outputs=None):
        self.path, self.line, self.text, self.kind = path, line, text, kind
        self.outputs = outputs or []

    def name(self):
        return f"{self.path}:{self.line}"


def parse(path):
    """(commands, demo blocks, skip texts) of a markdown file."""
    items, demo_blocks, skips = [], [], []
    lines = open(path, encoding="utf-8").read().split("\n")
    pending = None  # the marker before the next block
    i = 0
    while i < len(lines):
        line = lines[i]
        # (a marker is a line of its own: one quoted in a code span is text)
        for m in (MARKER.finditer(line) if line.strip().startswith("<!--") else ()):
            spec = m.group(1)
            q = re.match(r'skip\s+"([^"]+)"\s*(.*)', spec)
            if q:
                skips.append((q.group(1), q.group(2) or "marked"))
            else:
                pending = (spec, i + 1)
        if line.lstrip().startswith("```"):
            fence_line = i + 1
            body = []
            i += 1
            while i < len(lines) and not lines[i].lstrip().startswith("```"):
                body.append((i + 1, lines[i]))
                i += 1
            marker = pending[0] if pending and pending[1] >= fence_line - 2 else None
            pending = None
            if marker and marker.startswith("output of make demo"):
                demo_blocks.append(Item(path, fence_line, "make demo", "demo", [l for _, l in body]))
            elif marker and marker.startswith("skip"):
                items.append(Item(path, fence_line, "(block)", "skipped-block", [marker[4:].strip()]))
            else:
                items.extend(block_commands(path, body))
            i += 1
            continue
        if not line.strip().startswith("<!--"):
            for m in re.finditer(r"`([^`]+)`", line):
                items.append(Item(path, i + 1, m.group(1).strip(), "inline"))
        i += 1
    return items, demo_blocks, skips


def block_commands(path, body):
    """The commands of a fenced block, each with the output lines under it ("$ " blocks)."""
    prompt = any(l.startswith("$ ") for _, l in body)
    out, cur = [], None
    joined = []
    for n, l in body:  # join "\" continuations
        if joined and joined[-1][1].endswith("\\"):
            joined[-1] = (joined[-1][0], joined[-1][1][:-1] + " " + l.strip())
        else:
            joined.append((n, l))
    for n, l in joined:
        if prompt:
            if l.startswith("$ "):
                cur = Item(path, n, l[2:].strip(), "block")
                out.append(cur)
            elif cur is not None:
                cur.outputs.append(l)
        elif l.strip() and not l.strip().startswith("#"):
            out.append(Item(path, n, l.strip(), "block"))
    return out


def words(text):
    try:
        return shlex.split(text, comments=True)
    except ValueError:
        return None


def classify(item, skips):
    """(None, argv) to run it, ('ignore', '') when it is no j288 command, or (why, '')."""
    for text, why in skips:
        if text in item.text:
            return f"marked: {why}", None
    w = words(item.text)
    if not w:
        return "ignore", None
    k = 0
    while k < len(w) and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", w[k]):
        k += 1
    if k == len(w):
        return "ignore", None
    prog = os.path.basename(w[k]) if w[k].startswith(("build/bin/", "./build/bin/")) else w[k]
    if prog not in PROGRAMS:
        return "ignore", None
    args = w[k + 1:]
    if len(args) > 0 and args[0].endswith(":") or (item.kind == "inline" and ":" in item.text.split()[0]):
        return "a message, not a command", None
    hex_args = prog == "j288" and any(a in ("encode", "decode") for a in args)
    if any(s in item.text for s in ("[", "|", "...", "\u2026", "<")) or (not hex_args and any(
            all(PLACEHOLDER.match(p) for p in a.split(",") if p) for a in args if not a.startswith("-"))):
        return "syntax with placeholders", None
    if item.kind == "inline" and not any(a.startswith("--") for a in args):
        return "names a command", None
    if item.kind == "inline" and prog == "j288" and not any(a in COMMANDS for a in args):
        return "names an option", None
    return None, w


def mapped(argv, dev, own_link):
    """argv with the docs' devices mapped (a j288-sim gets its own link)."""
    out = []
    for a in argv:
        for d in DEVICES:
            a = re.sub(r"(?<![\w/.-])" + re.escape(d) + r"(?![\w/-])", own_link or dev, a)
        out.append(a)
    return out


OFFLINE = {"encode", "decode", "plot", "help"}
LOADED_MARGIN = "1000000"


def with_margin(argv):
    """A j288 bus command with --margin-us 1000000 before it (unless it gives one): the reply
    margin of a loaded machine, where the pseudo-terminal's default (5 ms) misses replies."""
    k = next(i for i, a in enumerate(argv) if not re.match(r"^[A-Za-z_]\w*=", a))
    rest = argv[k + 1:]
    if os.path.basename(argv[k]) != "j288" or any(a.startswith("--margin-us") for a in rest) or \
            any(a in OFFLINE or a in ("--help", "-h", "--version") for a in rest):
        return argv
    return argv[:k + 1] + ["--margin-us", LOADED_MARGIN] + rest


def long_running(argv):
    """A command that runs until Ctrl-C: how to tell it is running ('foc' or 'sim')."""
    prog = os.path.basename(next(a for a in argv if not re.match(r"^[A-Za-z_]\w*=", a)))
    if prog == "j288-sim":
        return None if any(a in ("--help", "-h", "--version") for a in argv) else "sim"
    cmds = [a for a in argv if a in ("hold", "move", "torque")]
    if cmds and not any(a.startswith(("--duration", "--arrive", "--help")) for a in argv):
        return "foc"
    return None


def log_lines(log):
    try:
        with open(log, encoding="utf-8", errors="replace") as f:
            return f.read().split("\n")
    except OSError:
        return []


def run(argv, args, kind_long, link):
    """(exit status, output) of one command, interrupted as the convention says."""
    env = dict(os.environ)
    env["PATH"] = os.path.join(args.work, "build", "bin") + os.pathsep + env["PATH"]
    env.pop("J288_QUIET", None)  # the notes a user sees are part of the output checked
    env["J288_PORT"] = args.dev  # a command shown without --port: the reader's default device
    assigns = []
    while argv and re.match(r"^[A-Za-z_]\w*=", argv[0]):
        assigns.append(argv.pop(0))
    for a in assigns:
        k, v = a.split("=", 1)
        env[k] = v
    mark = len(log_lines(args.log))
    p = subprocess.Popen(argv, cwd=args.work, env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    if kind_long:
        end = time.monotonic() + BOUND
        while time.monotonic() < end and p.poll() is None:
            if kind_long == "sim" and os.path.lexists(link):
                break
            if kind_long == "foc" and any(" status=1 " in l for l in log_lines(args.log)[mark:]):
                break
            time.sleep(0.05)
        if p.poll() is None:
            p.send_signal(signal.SIGTERM if kind_long == "sim" else signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=BOUND)
    except subprocess.TimeoutExpired:
        p.kill()
        out, _ = p.communicate()
        return None, out.decode("utf-8", "replace")
    return p.returncode, out.decode("utf-8", "replace")


def pattern(doc_line):
    """A documented output line as a regex over a printed line (None: lines left out)."""
    s = doc_line.rstrip()
    if s.strip() in ("...", "\u2026", ""):
        return None
    prefix = s.endswith("...") or s.endswith("\u2026")
    if prefix:
        s = s[:-3] if s.endswith("...") else s[:-1]
    out = ""
    for tok in re.split(r"(-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?| +)", s):
        if not tok:
            continue
        if re.fullmatch(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", tok):
            out += r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
        elif tok.strip() == "":
            out += r" +"
        else:
            out += re.escape(tok)
    return re.compile("^" + out.rstrip() + ("" if prefix else r" *$"))


def check_output(doc_lines, printed):
    """None when every documented line matches a printed one, in order; else what did not."""
    lines = printed.split("\n")
    at = 0
    for d in doc_lines:
        pat = pattern(d)
        if pat is None:
            continue
        while at < len(lines) and not pat.search(lines[at].rstrip()):
            at += 1
        if at == len(lines):
            return f"documented output line not printed (in order): {d.strip()!r}"
        at += 1
    return None


def run_demo(args):
    env = dict(os.environ, BUILD=os.path.join(args.work, "build"), BIN=args.bin)
    env.pop("J288_QUIET", None)
    p = subprocess.run(["bash", "scripts/demo.sh"], env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, timeout=BOUND * 2)
    out = p.stdout.decode("utf-8", "replace")
    # the docs show the default build folder
    out = out.replace(os.path.join(args.work, "build"), "build").replace(args.bin, "build/bin")
    return p.returncode, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("-v", action="store_true")
    for o in ("--dev", "--log", "--bin", "--work"):
        ap.add_argument(o, required=True)
    ap.add_argument("files", nargs="+")
    args = ap.parse_args()
    args.bin = os.path.abspath(args.bin)
    tests = failures = 0
    counts = {}
    demo_out = None
    t0 = time.monotonic()
    for path in args.files:
        items, demos, skips = parse(path)
        for it in items:
            if it.kind == "skipped-block":
                counts["marked"] = counts.get("marked", 0) + 1
                if args.v:
                    print(f"docs_run:{it.name()}:not run: marked: {it.outputs[0]}")
                continue
            why, argv = classify(it, skips)
            if why == "ignore":
                continue
            if why:
                counts[why.split(":")[0]] = counts.get(why.split(":")[0], 0) + 1
                if args.v:
                    print(f"docs_run:{it.name()}:not run ({why}): {it.text}")
                continue
            tests += 1
            own = os.path.join(args.work, f"sim{tests}.link") if "j288-sim" in os.path.basename(
                next(a for a in argv if not re.match(r"^[A-Za-z_]\w*=", a))) else None
            argv = with_margin(mapped(argv, args.dev, own))
            if own and "--link" not in argv:
                argv += ["--link", own]  # to tell when it serves
            if argv[0].startswith("./"):
                argv[0] = argv[0][2:]
            kind_long = long_running(argv)
            t1 = time.monotonic()
            rc, out = run(list(argv), args, kind_long, own)
            secs = time.monotonic() - t1
            printed = out.replace(args.dev, next((d for d in DEVICES if d in it.text), args.dev))
            want = {"foc": 130, "sim": 0}.get(kind_long, 0)
            bad = None
            if rc is None:
                bad = f"did not end within {BOUND} s"
            elif "jog" in argv and rc == 2 and "needs a terminal" in out:
                pass  # its options all taken; cli_jog.sh runs it on a terminal
            elif rc != want:
                bad = f"exit {rc}, want {want}"
            elif it.outputs:
                bad = check_output(it.outputs, printed)
            if bad:
                failures += 1
                print(f"docs_run:{it.name()}:FAIL: {bad}\n  $ {it.text}\n  ran: {shlex.join(argv)}\n"
                      + "".join("  | " + l + "\n" for l in out.rstrip().split("\n")[-15:]))
            else:
                print(f"docs_run:{it.name()}:PASS" + (f" ({secs:.1f} s): {it.text}" if args.v else ""))
        for d in demos:
            if shutil.which("gnuplot") is None and os.environ.get("CI") != "true":
                print(f"docs_run:{d.name()}:not run: the output of make demo shows its plot: "
                      "apt-get install gnuplot-nox")
                continue
            tests += 1
            if demo_out is None:
                demo_out = run_demo(args)
                if demo_out[0] != 0:  # (its 5 ms pty margin can miss a reply on a loaded
                    demo_out = run_demo(args)  # machine: once more; a drift fails both)
            rc, out = demo_out
            bad = f"make demo: exit {rc}" if rc != 0 else check_output(d.outputs, out)
            if bad:
                failures += 1
                print(f"docs_run:{d.name()}:FAIL: {bad}\n" + "".join("  | " + l + "\n" for l in out.split("\n")))
            else:
                print(f"docs_run:{d.name()}:PASS: the output of make demo")
    print(f"docs_run: {' '.join(args.files)}: {tests} run in {time.monotonic() - t0:.0f} s; not run: "
          + (", ".join(f"{n} {k}" for k, n in sorted(counts.items())) or "none"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
