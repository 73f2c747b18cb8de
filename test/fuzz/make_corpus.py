#!/usr/bin/env python3
"""Write the seed corpora of the fuzz targets into test/fuzz/corpus/<target>/.

Seeds are built from the golden vectors in test/vectors/ (commands.txt, replies.txt), which
come from the independent generator in tools/vectors/, arranged in each target's input
layout (see the comment at the top of each test/fuzz/fuzz_<target>.c). Deterministic: the
same vectors give the same files. Run `make fuzz-corpus` after the vectors or a target's
input layout change, and commit the result (keep it small: tens of files per target).
"""
import os
import random
import struct
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VEC = os.path.join(ROOT, "test", "vectors")
OUT = os.path.join(ROOT, "test", "fuzz", "corpus")


def read_vectors(name):
    rows = []
    with open(os.path.join(VEC, name)) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            rows.append(line.split())
    return rows


def write(target, name, data):
    d = os.path.join(OUT, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(bytes(data))


def clear(target):
    d = os.path.join(OUT, target)
    if os.path.isdir(d):
        for n in os.listdir(d):
            if n.startswith("seed_"):
                os.remove(os.path.join(d, n))


def main():
    rng = random.Random(288)
    cmds = read_vectors("commands.txt")
    replies = read_vectors("replies.txt")
    cmd_frames = [(r[0], bytes.fromhex(r[-1])) for r in cmds]
    rpl_frames = [(r[0], bytes.fromhex(r[-1])) for r in replies]
    # A spread of vectors, not all of them: the corpus stays small.
    cmd_pick = cmd_frames[:: max(1, len(cmd_frames) // 8)][:8]
    rpl_pick = rpl_frames[:: max(1, len(rpl_frames) // 8)][:8]

    for t in ("parser", "codec", "units", "cli"):
        clear(t)

    # parser: flags, nchunks, chunk sizes, stream.
    def noise(n):
        return bytes(rng.randrange(256) for _ in range(n))

    for i, (name, f) in enumerate(rpl_pick):
        write("parser", "seed_reply_whole_%s" % name, [0, 0] + list(f))
        bad = bytearray(f)
        bad[10] ^= 0x40
        stream = noise(5) + f + bytes(bad) + b"\xfc" + f + b"\xfc\xee\x01" + f[:13]
        chunks = [1 + i, 0x80 | 7, 26, 0x40, 3]
        write("parser", "seed_reply_mixed_%s" % name,
              [(i % 4) << 1, len(chunks)] + chunks + list(stream))
    for i, (name, f) in enumerate(cmd_pick[:4]):
        stream = noise(3) + f + f[:7] + f
        chunks = [20, 0x80 | 11, 2]
        write("parser", "seed_cmd_%s" % name, [1 | ((i % 4) << 1), len(chunks)] + chunks + list(stream))
    # a false head inside a payload, followed by the real frame
    f = rpl_frames[0][1]
    write("parser", "seed_false_head", [0, 1, 9] + list(b"\xfc\xee" + f[:4] + f))
    # large chunks, so that whole frames are checked where they lie (the target compares with
    # the byte path): doubled and false heads, a corrupt frame then a good one, a frame that
    # starts inside a corrupt one, frames across chunk ends
    g = rpl_frames[1][1]
    bad = bytearray(g)
    bad[7] ^= 0x04
    stream = (b"\xfc\xfc\xee" + f + b"\xfc" + bytes(bad) + g + b"\xfc\xee" + f[2:] + f +
              bytes(bad[:9]) + g + f[:11])
    write("parser", "seed_fast_path_reply", [0, 2, 63, 0x80 | 40] + list(stream))
    c = cmd_frames[0][1]
    bad = bytearray(c)
    bad[5] ^= 0x10
    stream = b"\xfe\xfe\xee" + c + bytes(bad) + c + c[:9] + c + c[:3]
    write("parser", "seed_fast_path_cmd", [1 | (1 << 1), 1, 63] + list(stream))

    # codec: byte 0 = case (low 3 bits) | crc engine (bits 3-4) | fix head 0x40 | fix crc 0x80.
    for i, (name, f) in enumerate(rpl_pick):
        write("codec", "seed_rdec_%s" % name, [0 | ((i % 3) << 3)] + list(f))
    for i, (name, f) in enumerate(cmd_pick):
        write("codec", "seed_cdec_%s" % name, [1 | ((i % 3) << 3)] + list(f))
    write("codec", "seed_rdec_fixcrc", [0xC0] + list(noise(26)))
    write("codec", "seed_cdec_fixcrc", [0xC1] + list(noise(20)))
    for r in cmds[:: max(1, len(cmds) // 6)][:6]:
        name, cid, st, wd, tau, spd, pos, kp, kd, res = r[:10]
        data = struct.pack("<BBBhhihhB", int(cid), int(st), int(wd), int(tau), int(spd),
                           int(pos), int(kp), int(kd), int(res))
        write("codec", "seed_cenc_%s" % name, [2] + list(data))
    for r in replies[:: max(1, len(replies) // 6)][:6]:
        (name, rid, st, wd, ct, wt, vol, tq, spd, pos, faults, outp, warn, res) = r[:14]
        data = struct.pack("<BBBbBBhhiIHBH", int(rid), int(st), int(wd), int(ct), int(wt),
                           int(vol), int(tq), int(spd), int(pos), int(faults, 16), int(outp),
                           int(warn), int(res))
        write("codec", "seed_renc_%s" % name, [3] + list(data))
    write("codec", "seed_crc_check", [4, 1] + list(b"123456789abc"))
    write("codec", "seed_crc_frame", [5, 2] + list(rpl_frames[0][1][2:22]) + [0xff] * 5)

    # units: flags (bit 0 output side, bit 1 raw round trip), then 5 values.
    def dbl(*v):
        return b"".join(struct.pack("<d", x) for x in v)

    write("units", "seed_si_zero", [0] + list(dbl(0, 0, 0, 0, 0)))
    write("units", "seed_si_small", [0] + list(dbl(0.01, -3.0, 1.0, 0.001, 0.0001)))
    write("units", "seed_si_out", [1] + list(dbl(2.0, -0.5, 0.3, 50.0, 5.0)))
    write("units", "seed_si_edges", [0] + list(dbl(0.128, 80423.0, 411775.0, 0.0256, 0.000256)))
    write("units", "seed_si_bad", [1] + list(dbl(float("nan"), float("inf"), -1e300, -1.0, 1e-320)))
    write("units", "seed_si_half", [0] + list(dbl(32767.5 / 256000.0, -32768.5 / 256000.0, 0, 0, 0)))
    write("units", "seed_raw_rotor", [2] + list(struct.pack("<BBhhihh", 3, 1, -700, 41, 5215, 1280, 12800)) + [0xe8, 3, 48])
    write("units", "seed_raw_output", [3] + list(struct.pack("<BBhhihh", 7, 1, 32767, -32768, -2**31, 32767, 0)) + [0xff, 0xff, 255])

    # cli: byte 0 = case (0 hex, 1 arguments, 2 integer, 3 real, 4 id list), bytes 1-2 =
    # parameters, then the text.
    write("cli", "seed_hex_spec", [0, 30, 60] + list(" ".join("%02x" % b for b in cmd_frames[0][1]).encode()))
    write("cli", "seed_hex_forms", [0, 5, 10] + list(b"0xfe,0xEE:80 1d"))
    write("cli", "seed_hex_odd", [0, 3, 2] + list(b"fee"))
    write("cli", "seed_args", [1, 0, 0] + list(b"--id\x003\x00--flag\x00--tau=-0.5\x00pos\x00--\x00--id"))
    write("cli", "seed_args_help", [1, 0, 0] + list(b"-h\x00--port"))
    for i, t in enumerate([b"3", b"-0x10", b"0x", b"+14", b"9223372036854775808", b" 3", b"010"]):
        write("cli", "seed_int_%d" % i, [2, i, 7 - i] + list(t))
    for i, t in enumerate([b"0.5", b"-1e3", b"nan", b"inf", b"1e999", b"0x1p3"]):
        write("cli", "seed_real_%d" % i, [3, 0, 0] + list(t))
    for i, t in enumerate([b"1,2,3", b"0,14", b"1,,2", b"3,3", b"15"]):
        write("cli", "seed_ids_%d" % i, [4, 14, 0] + list(t))
    return 0


if __name__ == "__main__":
    sys.exit(main())
