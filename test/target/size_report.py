#!/usr/bin/env python3
"""Flash/RAM per module and stack per public call for `make size`.

Usage: size_report.py VARIANT_DIR...   (each holds probe.map, probe.elf and obj/**/*.ci)
A variant dir is named <core>-<crc backend>. Flash = .text + .rodata + .data (its initial
values), RAM = .data + .bss, taken per input object from the linker map of the probe linked
with --gc-sections, i.e. only what a typical application really pulls in. Stack: from GCC's
-fcallgraph-info=su, the deepest path below each public function; an indirect call in the
library (port operation, CRC hook) counts as the deepest operation of the STM32 port or the
scheduler's completion callback; the application's own callbacks (clock, completion, events)
come on top. Recursion: the library has none. The one cycle in the static graph is the bus's
step loop entered again from inside a port call, which returns at once (in_advance), so it
counts with its own frame. Any other cycle is reported as an ERROR and make size fails.
Soft float: the floating-point helpers (__aeabi_d*, __aeabi_f*, integer <-> float) linked into
each probe are listed; in a build without the SI API (variant name ending -nosi or -jointq)
any of them is an ERROR.
"""
import os
import re
import sys
from collections import defaultdict

MODULES = ["frame", "crc32", "parser", "bus", "sched", "units", "jointq", "strerror", "abi", "j288_stm32"]


def parse_map(path):
    """{module: [flash, ram]} from the 'Linker script and memory map' part of a GNU ld map."""
    sizes = defaultdict(lambda: [0, 0])
    text = open(path).read()
    text = text[text.find("Linker script and memory map"):]
    pending = None
    for line in text.splitlines():
        m = re.match(r"^ (\.\S+|COMMON)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (\.\S+|COMMON)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+\.o\)?|\S+\.a\(\S+\))\s*$", line)
        if not m:
            pending = None if not line.startswith("  ") else pending
            continue
        sect = m.group(1) or pending
        pending = None
        size = int(m.group(3), 16)
        src = m.group(4)
        if sect is None or size == 0:
            continue
        base = os.path.basename(src)
        mod = base[:-2] if base.endswith(".o") else ("libc/libgcc" if ".a(" in base else base)
        if mod not in MODULES and mod not in ("size_probe", "stm32_hal_stub"):
            mod = "libc/libgcc"
        if sect.startswith((".text", ".rodata")):
            sizes[mod][0] += size
        elif sect.startswith(".data"):
            sizes[mod][0] += size
            sizes[mod][1] += size
        elif sect.startswith((".bss", "COMMON")):
            sizes[mod][1] += size
    return sizes


SOFT_FLOAT = re.compile(r"^\s+0x[0-9a-f]+\s+(__aeabi_(?:[df][a-z]\w*|[df]2\w+|u?[il]2[df]))\s*$")


def soft_float_symbols(map_path):
    """Soft-float helpers the probe links (their definitions in the map's memory map)."""
    text = open(map_path).read()
    text = text[text.find("Linker script and memory map"):]
    return sorted({m.group(1) for m in map(SOFT_FLOAT.match, text.splitlines()) if m})


def parse_ci(root):
    nodes, edges = {}, defaultdict(set)
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".ci"):
                continue
            for line in open(os.path.join(dirpath, f)):
                m = re.match(r'node: \{ title: "([^"]+)" label: "[^"]*\\n(\d+) bytes \(([^)]*)\)', line)
                if m:
                    nodes[m.group(1)] = (int(m.group(2)), m.group(3))
                    continue
                m = re.match(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', line)
                if m:
                    edges[m.group(1)].add(m.group(2))
    return nodes, edges


# The bus's step loop: entered again from inside a port call (op_start_rx -> rx_arm ->
# j288_bus_on_error -> advance_from_event -> advance), it returns at once (in_advance), so on a
# path that is already inside it only its own frame counts.
REENTRY_GUARD = re.compile(r"lib/src/bus\.c:(advance|reply_fast)(\.\w+)*$")
# Indirect calls that go to the application (its clock, its event callback): on top, like the
# completion callbacks.
# What each indirect call site in the library calls, read from the source: port operations
# by member name (op_<member> in the STM32 port), "sched_done" for the bus's completion
# callback when the scheduler drives the bus, "app" for the application's own function
# pointers (its clock, its event callback: on top, like the completion callbacks). A site not
# listed here counts as every port operation and the scheduler's callback, with a note.
INDIRECT_SITES = [
    (r"bus\.c:arm_at", ["arm_timeout"]),
    (r"bus\.c:finish", ["sched_done"]),
    (r"bus\.c:port_lock", ["lock"]),
    (r"bus\.c:port_unlock", ["unlock"]),
    (r"(bus|sched)\.c:j288_bus_lock", ["lock"]),
    (r"(bus|sched)\.c:j288_bus_unlock", ["unlock"]),
    (r"bus\.c:start_attempt(_called)?", ["set_dir", "start_tx", "start_rx", "now_us"]),
    (r"bus\.c:advance_from_event", ["now_us"]),
    (r"bus\.c:(take_in_place|tx_done_fast)", ["now_us"]),
    (r"bus\.c:reply_fast", ["now_us", "crc32"]),
    (r"^j288_bus_on_tx_done", ["set_dir", "start_rx", "now_us"]),
    (r"^j288_bus_on_rx", ["now_us"]),
    (r"^j288_bus_transfer_blocking", ["wait", "now_us", "lock", "unlock"]),
    (r"^j288_crc32_run", ["crc32"]),
    (r"^j288_cmd_(encode|pack)", ["crc32"]),  # the frame's CRC, inlined
    (r"^j288_parser_feed", ["crc32"]),
    (r"^j288_sched_set_cmd", ["lock", "unlock", "crc32"]),  # j288_cmd_pack inlined
    (r"frame\.c:j288_crc_frame", ["crc32"]),
    (r"parser\.c:frame_crc_ok", ["crc32"]),
    (r"(parser|bus|frame)\.c:j288_crc_frame_hot", ["crc32"]),
    (r"sched\.c:(next_slot|sched_lock|sched_unlock)", ["lock", "unlock"]),
    (r"sched\.c:(emit|sched_done|take_reply)", ["app"]),
    (r"^j288_joint(q)?_(bus_on_reply|after_reply)|joint(q)?\.c:(jq_)?report", ["app"]),  # on_event
    (r"joint\.c:event_to_real", ["app"]),  # the facade's on_event
    (r"j288_stm32\.c:now_of", ["app"]),
]


def stack_depths(nodes, edges):
    """{public function: deepest stack}, notes, cycles.

    Exact longest path, memoised per (function, inside the step loop already): that flag is
    the only thing a depth depends on when the call graph has no cycle besides the guarded
    re-entry. Any other cycle is recursion the library must not have: it is cut, reported in
    `cycles`, and no depth computed below a cut is memoised (each caller gets its own, the
    figures marked as lower bounds by the caller)."""
    ops = {n.split(":op_")[1].split(".")[0]: n for n in nodes if re.search(r"j288_stm32\.c:op_", n)}
    done_cbs = [n for n in nodes if re.search(r"sched\.c:sched_done(\.\w+)*$", n)]
    memo = {}
    notes = set()
    cycles = set()

    def indirect_targets(n):
        for pat, members in INDIRECT_SITES:
            if re.search(pat + r"(\.\w+)*$", n):
                break
        else:
            notes.add("indirect call in %s not in INDIRECT_SITES: counted as any port operation" % n)
            members = list(ops) + ["sched_done"]
        for m in members:
            if m == "app":
                notes.add(n.split(":")[-1] + ": the application's function pointer, not counted")
            elif m == "sched_done":
                yield from done_cbs
            elif m in ops:
                yield ops[m]

    def targets(n):
        for t in edges.get(n, ()):
            if t == "__indirect_call":
                yield from indirect_targets(n)
            else:
                yield t

    def depth(n, guarded, path):
        own, kind = nodes.get(n, (0, "static"))
        if guarded and REENTRY_GUARD.search(n):
            notes.add("bus.c:advance re-entered from a port call returns at once: counted as its own frame")
            return own, True
        if (n, guarded) in memo:
            return memo[(n, guarded)], True
        # A call state is (function, inside the step loop): the flag only turns on along a
        # path, so a function met again with the other flag is not a cycle.
        if (n, guarded) in path:
            cyc = [m for m, _ in path[path.index((n, guarded)):]] + [n]
            cycles.add(" -> ".join(c.split(":")[-1] for c in cyc))
            if len(cycles) > 20:
                raise SystemExit("size_report.py: ERROR: more than 20 call cycles; first: " + sorted(cycles)[0])
            return 0, False
        if kind != "static":
            notes.add(n.split(":")[-1] + " has " + kind + " stack")
        path.append((n, guarded))
        # (The compiler may split the step loop into a wrapper and its .part clone: the guard
        # turns on in the part that runs the loop, not in a wrapper calling it.)
        inner = guarded or (bool(REENTRY_GUARD.search(n)) and
                            not any(REENTRY_GUARD.search(t) for t in edges.get(n, ())))
        deepest, clean = 0, True
        for t in targets(n):
            d, c = depth(t, inner, path)
            deepest = max(deepest, d)
            clean = clean and c
        path.pop()
        if clean:
            memo[(n, guarded)] = own + deepest
        return own + deepest, clean

    result = {}
    for n in sorted(nodes):
        if ":" in n or not n.startswith("j288_"):
            continue  # static helpers carry a file: prefix
        d, clean = depth(n, False, [])
        result[n] = d if clean else ">= %d (cycle)" % d
    return result, notes, cycles


def main(dirs):
    maps = {os.path.basename(d.rstrip("/")): parse_map(os.path.join(d, "probe.map")) for d in dirs}
    names = list(maps)
    print("Flash / RAM in bytes per module (-Os, --gc-sections, the size probe's use of the API):")
    print()
    print("| module | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    mods = MODULES + ["libc/libgcc"]
    totals = {n: [0, 0] for n in names}
    for mod in mods:
        cells = []
        for n in names:
            f, r = maps[n].get(mod, [0, 0])
            totals[n][0] += f
            totals[n][1] += r
            cells.append("%d / %d" % (f, r))
        label = {"j288_stm32": "port/stm32_hal", "libc/libgcc": "libc + libgcc (memcpy, soft float)"}.get(mod, mod)
        print("| %s | %s |" % (label, " | ".join(cells)))
    print("| **total** | " + " | ".join("**%d / %d**" % tuple(totals[n]) for n in names) + " |")
    print()
    print("Caller-allocated objects (RAM, from the probe's symbols):")
    print()
    for d in dirs:
        syms = {}
        for line in os.popen("arm-none-eabi-nm -S --size-sort '%s'" % os.path.join(d, "probe.elf")):
            parts = line.split()
            if len(parts) == 4 and parts[3] in ("probe_port", "probe_sched", "probe_dma",
                                                "probe_joints", "probe_jbus"):
                syms[parts[3]] = int(parts[1], 16)
        print("- %s: j288_stm32_t (includes j288_bus_t) %d, j288_sched_t %d, DMA buffers %d" % (
            os.path.basename(d.rstrip("/")), syms.get("probe_port", 0), syms.get("probe_sched", 0),
            syms.get("probe_dma", 0)) + (
                ", 15 j288_jointq_t %d, j288_jointq_bus_t %d" % (syms["probe_joints"], syms.get("probe_jbus", 0))
                if "probe_joints" in syms else ""))
    print()
    soft_errors = []
    print("Soft-float helpers linked:")
    print()
    for d in dirs:
        name = os.path.basename(d.rstrip("/"))
        found = soft_float_symbols(os.path.join(d, "probe.map"))
        print("- %s: %s" % (name, ("%d (%s)" % (len(found), ", ".join(found))) if found else "none"))
        if found and name.endswith(("-nosi", "-jointq")):
            soft_errors.append("ERROR: %s has no SI API but links soft float: %s" % (name, ", ".join(found)))
    for e in soft_errors:
        print(e)
        print("size_report.py: " + e, file=sys.stderr)
    print()
    stacks = {}
    all_notes = set()
    all_cycles = set()
    for d in dirs:
        nodes, edges = parse_ci(os.path.join(d, "obj"))
        stacks[os.path.basename(d.rstrip("/"))], notes, cycles = stack_depths(nodes, edges)
        all_notes |= notes
        all_cycles |= cycles
    print("Stack per public call in bytes (deepest path; indirect calls = the deepest port operation;")
    print("the application's completion and event callbacks come on top):")
    print()
    print("| function | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    funcs = sorted(set().union(*[set(s) for s in stacks.values()]))
    for fn in funcs:
        print("| %s | %s |" % (fn, " | ".join(str(stacks[n].get(fn, "-")) for n in names)))
    if all_notes:
        print()
        for n in sorted(all_notes):
            print("note: " + n)
    if soft_errors:
        return 1
    if all_cycles:
        print()
        for c in sorted(all_cycles):
            msg = "ERROR: recursion in the call graph (stack unbounded, figures above are lower bounds): " + c
            print(msg)
            print("size_report.py: " + msg, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
