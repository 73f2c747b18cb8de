#!/usr/bin/env python3
"""Golden-vector generator for the j288 servo protocol.

Written from the protocol description alone (docs/protocol.md), independently of the C
library: frames are packed with struct, the CRC is computed two unrelated ways (the manual's
word-wise crc32_core loop, and a bitwise CRC-32/MPEG-2 over the byte stream with every 4-byte
group reversed) that must agree on every frame, and SI conversions are evaluated with exact
rational arithmetic and rounded half away from zero here.

Standard library only. Deterministic: the same output on every run and every Python 3.

    python3 tools/vectors/gen_vectors.py [--out DIR]     (default DIR: test/vectors)

writes commands.txt, replies.txt, si.txt, si_commands.txt, fixed.txt and golden_vectors.h.
"""

import argparse
import math
import os
import struct
import sys
from fractions import Fraction

# ---------------------------------------------------------------------------------------------
# Protocol constants (from the protocol description).

CMD_LEN = 20
REPLY_LEN = 26
CMD_HEAD = b"\xfe\xee"
REPLY_HEAD = b"\xfc\xee"
POLY = 0x04C11DB7
GEAR = Fraction("288.35")
# pi to 60 digits: the "exact" reference for the scale factors that involve 2 pi.
PI = Fraction("3.14159265358979323846264338327950288419716939937510582097494459")

INT16 = (-(1 << 15), (1 << 15) - 1)
INT32 = (-(1 << 31), (1 << 31) - 1)

# LSB per SI unit, rotor side.
SCALE = {
    "torque": Fraction(256000),
    "speed": Fraction(256, 100) / (2 * PI),
    "pos": Fraction(32768) / (2 * PI),
    "kp": Fraction(1280000),
    "kd": Fraction(128000000),
}
# Output side = rotor side through the gear: angle and speed / N, torque * N, gains * N^2.
# So LSB per output-side unit: angles and speeds * N, torque / N, gains / N^2.
OUTPUT_FACTOR = {
    "torque": 1 / GEAR,
    "speed": GEAR,
    "pos": GEAR,
    "kp": 1 / (GEAR * GEAR),
    "kd": 1 / (GEAR * GEAR),
}
RANGE = {"torque": INT16, "speed": INT16, "pos": INT32, "kp": INT16, "kd": INT16}
RANGE_ERR = {
    "torque": "J288_ERR_RANGE_TAU",
    "speed": "J288_ERR_RANGE_SPEED",
    "pos": "J288_ERR_RANGE_POS",
    "kp": "J288_ERR_RANGE_KP",
    "kd": "J288_ERR_RANGE_KD",
}
QUANTITIES = ["torque", "speed", "pos", "kp", "kd"]
GAINS = ("kp", "kd")

FAULT_NAMES = [
    "over-current", "transient over-voltage", "sustained over-voltage", "under-voltage",
    "chip over-temperature", "MOSFET over/under-temperature", "MOSFET temperature abnormal",
    "case over/under-temperature", "case temperature abnormal", "winding over-temperature",
    "rotor encoder 1 error", "rotor encoder 2 error", "output encoder error",
    "stored data error", "abnormal reset", "waiting for unlock", "driver verification error",
    "calibration mode", "communication checksum error", "driver version too low",
    "firmware model error", "encoder angle abnormal",
]
WARNING_NAMES = ["low-voltage supply abnormal", "unknown warning", "unknown warning"]

# Error codes the vectors refer to (names only; their values live in the C header).
ERR_CODES = ["J288_OK", "J288_ERR_BAD_ID", "J288_ERR_BAD_STATUS", "J288_ERR_NEG_GAIN",
             "J288_ERR_RANGE_TAU", "J288_ERR_RANGE_SPEED", "J288_ERR_RANGE_POS",
             "J288_ERR_RANGE_KP", "J288_ERR_RANGE_KD", "J288_ERR_NOT_FINITE"]

# ---------------------------------------------------------------------------------------------
# CRC, two independent ways.


def crc_manual_words(words):
    """The manual's crc32_core, transcribed: shift, then XOR the poly in for each data bit."""
    crc = 0xFFFFFFFF
    for data in words:
        xbit = 0x80000000
        for _ in range(32):
            if crc & 0x80000000:
                crc = ((crc << 1) & 0xFFFFFFFF) ^ POLY
            else:
                crc = (crc << 1) & 0xFFFFFFFF
            if data & xbit:
                crc ^= POLY
            xbit >>= 1
    return crc


def crc_mpeg2_bytes(data):
    """Plain bitwise CRC-32/MPEG-2 over a byte stream (message bits MSB first)."""
    crc = 0xFFFFFFFF
    for byte in data:
        crc ^= byte << 24
        for _ in range(8):
            crc = ((crc << 1) ^ POLY) if crc & 0x80000000 else (crc << 1)
            crc &= 0xFFFFFFFF
    return crc


def frame_crc(data):
    """CRC of a frame region: both methods, which must agree."""
    assert len(data) % 4 == 0
    words = struct.unpack("<%dI" % (len(data) // 4), data)
    a = crc_manual_words(words)
    swapped = b"".join(data[i:i + 4][::-1] for i in range(0, len(data), 4))
    b = crc_mpeg2_bytes(swapped)
    if a != b:
        raise AssertionError("CRC methods disagree on %s: %08x %08x" % (data.hex(), a, b))
    return a


# ---------------------------------------------------------------------------------------------
# Frames.


def mode_byte(ident, status, flag):
    return (ident & 0x0F) | ((status & 0x07) << 4) | (0x80 if flag else 0)


def pack_command(c):
    body = CMD_HEAD + struct.pack("<BBhhihh", mode_byte(c["id"], c["status"], c["watchdog"]),
                                  c["reserved"], c["tau"], c["speed"], c["pos"], c["kp"],
                                  c["kd"])
    assert len(body) == 16
    return body + struct.pack("<I", frame_crc(body))


def pack_reply(r):
    out = (r["out_pos"] & 0x1FFF) | ((r["warnings"] & 0x7) << 13)
    body = struct.pack("<BbBBhhiIHH", mode_byte(r["id"], r["status"], r["watchdog"]),
                       r["case_temp"], r["winding_temp"], r["voltage"], r["torque"], r["speed"],
                       r["pos"], r["faults"], out, r["reserved"])
    assert len(body) == 20
    return REPLY_HEAD + body + struct.pack("<I", frame_crc(body))


def command_expect(c):
    """What an encoder must answer for these fields (order: id, status, gains)."""
    if not 0 <= c["id"] <= 15:
        return "J288_ERR_BAD_ID"
    if c["status"] not in (0, 1):
        return "J288_ERR_BAD_STATUS"
    if c["kp"] < 0 or c["kd"] < 0:
        return "J288_ERR_NEG_GAIN"
    if c["reserved"] != 0:
        return "decode_only"  # encoders always send reserved = 0
    return "ok"


def reply_expect(r):
    if not 0 <= r["id"] <= 14:
        return "J288_ERR_BAD_ID"  # 15 is broadcast: no servo ever replies as 15
    return "ok"


class XorShift32:
    """Tiny deterministic PRNG (Marsaglia xorshift32), so output never depends on Python's."""

    def __init__(self, seed):
        self.s = seed & 0xFFFFFFFF or 1

    def u32(self):
        s = self.s
        s ^= (s << 13) & 0xFFFFFFFF
        s ^= s >> 17
        s ^= (s << 5) & 0xFFFFFFFF
        self.s = s
        return s

    def below(self, n):
        return self.u32() % n

    def signed(self, bits):
        v = self.u32() & ((1 << bits) - 1)
        return v - (1 << bits) if v >= (1 << (bits - 1)) else v

    def pick(self, seq):
        return seq[self.below(len(seq))]


def cmd(name, ident=0, status=1, watchdog=1, tau=0, speed=0, pos=0, kp=0, kd=0, reserved=0):
    return {"name": name, "id": ident, "status": status, "watchdog": watchdog, "tau": tau,
            "speed": speed, "pos": pos, "kp": kp, "kd": kd, "reserved": reserved}


def reply(name, ident=0, status=1, watchdog=0, case_temp=25, winding_temp=30, voltage=48,
          torque=0, speed=0, pos=0, faults=0, out_pos=0, warnings=0, reserved=0):
    return {"name": name, "id": ident, "status": status, "watchdog": watchdog,
            "case_temp": case_temp, "winding_temp": winding_temp, "voltage": voltage,
            "torque": torque, "speed": speed, "pos": pos, "faults": faults,
            "out_pos": out_pos, "warnings": warnings, "reserved": reserved}


I16_EXTREMES = [-32768, -32767, -1, 0, 1, 32766, 32767]
I32_EXTREMES = [-2147483648, -2147483647, -65536, -1, 0, 1, 65535, 2147483646, 2147483647]
GAIN_EXTREMES = [0, 1, 255, 256, 32766, 32767]


def command_vectors():
    v = []
    # The spec's worked frames first.
    v.append(cmd("spec_lock_id0", 0, 0, 1))
    v.append(cmd("spec_foc_id3", 3, 1, 1, pos=5215, kp=1280, kd=12800))
    for ident in range(16):
        for status in (0, 1):
            for wd in (0, 1):
                v.append(cmd("mode_id%d_st%d_wd%d" % (ident, status, wd), ident, status, wd,
                             tau=ident * 100 - 700, pos=ident * 5215))
    for t in I16_EXTREMES:
        v.append(cmd("tau_%d" % t, 1, tau=t))
    for s in I16_EXTREMES:
        v.append(cmd("speed_%d" % s, 2, speed=s))
    for p in I32_EXTREMES:
        v.append(cmd("pos_%d" % p, 4, pos=p))
    for k in GAIN_EXTREMES:
        v.append(cmd("kp_%d" % k, 5, kp=k))
        v.append(cmd("kd_%d" % k, 6, kd=k))
    v.append(cmd("all_min", 14, 1, 1, -32768, -32768, -2147483648, 0, 0))
    v.append(cmd("all_max", 14, 1, 1, 32767, 32767, 2147483647, 32767, 32767))
    v.append(cmd("all_max_broadcast", 15, 1, 0, 32767, 32767, 2147483647, 32767, 32767))
    v.append(cmd("broadcast_lock", 15, 0, 0))
    # Byte patterns that look like heads inside the payload (parser food).
    v.append(cmd("false_head_fe_ee_in_tau", 7, tau=-4354))      # 0xeefe
    v.append(cmd("false_head_fc_ee_in_pos", 7, pos=0x00EEFCEE))
    v.append(cmd("false_head_fc_ee_in_speed", 7, speed=-4356))  # 0xeefc
    # Decoders report what the wire says, even what an encoder would refuse.
    for status in range(2, 8):
        for wd in (0, 1):
            v.append(cmd("status%d_wd%d" % (status, wd), 9, status, wd, tau=status))
    for k in (-1, -32768):
        v.append(cmd("neg_kp_%d" % -k, 10, kp=k))
        v.append(cmd("neg_kd_%d" % -k, 10, kd=k))
    v.append(cmd("reserved_ff", 11, reserved=0xFF))
    v.append(cmd("reserved_01", 11, reserved=0x01))
    rng = XorShift32(0x288C0DE1)
    for i in range(220):
        v.append(cmd("random_%03d" % i, rng.below(16), rng.below(2), rng.below(2),
                     rng.signed(16), rng.signed(16), rng.signed(32), rng.below(32768),
                     rng.below(32768)))
    return v


def reply_vectors():
    v = []
    v.append(reply("spec_reply_id3", 3, 1, 0, 36, 41, 48, 1280, -41, 5215, 0, 1000))
    for ident in range(16):
        for wd in (0, 1):
            v.append(reply("id%d_wd%d" % (ident, wd), ident, 1, wd, pos=ident * 1000 - 7000,
                           out_pos=ident * 512))
    for status in range(8):
        v.append(reply("status%d" % status, 2, status))
    for bit in range(32):
        v.append(reply("fault_bit%d" % bit, 4, faults=1 << bit))
    v.append(reply("faults_all_known", 4, faults=(1 << 22) - 1))
    v.append(reply("faults_all_ones", 4, faults=0xFFFFFFFF))
    v.append(reply("faults_unknown_only", 4, faults=0xFFC00000))
    for w in range(8):
        v.append(reply("warnings_%d" % w, 5, warnings=w, out_pos=4096))
    for o in (0, 1, 1000, 4095, 4096, 8190, 8191):
        v.append(reply("out_pos_%d" % o, 6, out_pos=o))
        v.append(reply("out_pos_%d_warn7" % o, 6, out_pos=o, warnings=7))
    for t in (-128, -127, -40, -1, 0, 1, 85, 127):
        v.append(reply("case_temp_%d" % t, 7, case_temp=t))
    for t in (0, 1, 127, 128, 200, 255):
        v.append(reply("winding_temp_%d" % t, 7, winding_temp=t))
    for vol in (0, 1, 24, 48, 50, 100, 254, 255):
        v.append(reply("voltage_%d" % vol, 8, voltage=vol))
    for t in I16_EXTREMES:
        v.append(reply("torque_%d" % t, 9, torque=t))
    for s in I16_EXTREMES:
        v.append(reply("speed_%d" % s, 10, speed=s))
    for p in I32_EXTREMES:
        v.append(reply("pos_%d" % p, 11, pos=p))
    for r in (0, 1, 0xEEFC, 0xFFFF):
        v.append(reply("reserved_%04x" % r, 12, reserved=r))
    v.append(reply("all_min", 0, 0, 0, -128, 0, 0, -32768, -32768, -2147483648, 0, 0, 0))
    v.append(reply("all_max", 14, 7, 1, 127, 255, 255, 32767, 32767, 2147483647, 0xFFFFFFFF,
                   8191, 7, 0xFFFF))
    v.append(reply("false_head_fc_ee_in_pos", 13, pos=0x12EEFCEE))
    v.append(reply("false_head_fc_ee_in_faults", 13, faults=0x00EEFC00))
    rng = XorShift32(0x288FACE5)
    for i in range(200):
        faults = rng.u32() if rng.below(4) == 0 else (rng.u32() & ((1 << 22) - 1) if rng.below(2)
                                                       else 0)
        v.append(reply("random_%03d" % i, rng.below(15), rng.below(8), rng.below(2),
                       rng.signed(8), rng.below(256), rng.below(256), rng.signed(16),
                       rng.signed(16), rng.signed(32), faults, rng.below(8192), rng.below(8),
                       rng.below(65536) if rng.below(8) == 0 else 0))
    return v


# ---------------------------------------------------------------------------------------------
# SI conversions, exactly.


def lsb_per_unit(q, side):
    k = SCALE[q]
    return k * OUTPUT_FACTOR[q] if side == "output" else k


def round_half_away(x):
    """Nearest integer to a Fraction, halves away from zero."""
    a = abs(x)
    n = math.floor(a)
    if a - n >= Fraction(1, 2):
        n += 1
    return n if x >= 0 else -n


def to_raw_exact(q, side, si):
    """(expect, raw) for one SI value under the project's policy, computed exactly."""
    if isinstance(si, float) and math.isnan(si):
        return "J288_ERR_NOT_FINITE", 0
    if q in GAINS and si < 0:
        return "J288_ERR_NEG_GAIN", 0
    lo, hi = RANGE[q]
    if isinstance(si, float) and math.isinf(si):
        return RANGE_ERR[q], 0
    r = round_half_away(Fraction(si) * lsb_per_unit(q, side))
    if r < lo or r > hi:
        return RANGE_ERR[q], 0
    return "ok", r


def clamp_exact(q, side, si):
    """(clamped?, raw) for the saturating variant (NaN is refused elsewhere)."""
    expect, raw = to_raw_exact(q, side, si)
    lo, hi = RANGE[q]
    if expect == "ok":
        return False, raw
    if expect == "J288_ERR_NEG_GAIN":
        return True, 0
    return True, (lo if si < 0 else hi)


def outcome_scaled(q, side, si, factor):
    """to_raw_exact as if the product were off by the relative factor (1 +- eps)."""
    if isinstance(si, float) and (math.isnan(si) or math.isinf(si)):
        return to_raw_exact(q, side, si)
    if q in GAINS and si < 0:
        return to_raw_exact(q, side, si)
    lo, hi = RANGE[q]
    r = round_half_away(Fraction(si) * lsb_per_unit(q, side) * factor)
    return ("ok", r) if lo <= r <= hi else (RANGE_ERR[q], 0)


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def exact_in_binary(q, side, si, to_float):
    """A rotor-side integer-scale product that no rounding disturbs (deliberate half ties)."""
    if side != "rotor" or SCALE[q].denominator != 1 or isinstance(si, float) and not math.isfinite(si):
        return False
    if to_float:
        if f32(si) != si:
            return False
        prod = Fraction(si) * SCALE[q]
        try:
            return Fraction(f32(float(prod))) == prod
        except OverflowError:
            return False
    prod = Fraction(si) * SCALE[q]
    return Fraction(float(prod)) == prod


def robust(q, side, si, eps):
    want = to_raw_exact(q, side, si)
    return all(outcome_scaled(q, side, si, Fraction(1) + s * eps) == want for s in (-1, 1))


EPS_DOUBLE = Fraction(1, 10**12)
EPS_FLOAT = Fraction(1, 1 << 20)


def si_case(name, q, side, si):
    """One SI -> raw vector, or None when double arithmetic could legitimately disagree."""
    if not (robust(q, side, si, EPS_DOUBLE) or exact_in_binary(q, side, si, False)):
        return None
    expect, raw = to_raw_exact(q, side, si)
    float_ok = robust(q, side, si, EPS_FLOAT) or exact_in_binary(q, side, si, True)
    return {"name": name, "q": q, "side": side, "si": si, "expect": expect, "raw": raw,
            "float_exact": 1 if float_ok else 0}


def si_vectors():
    out = []

    def add(name, q, side, si):
        c = si_case(name, q, side, si)
        if c is not None:
            out.append(c)
            return True
        return False

    for side in ("rotor", "output"):
        for q in QUANTITIES:
            k = lsb_per_unit(q, side)
            lo, hi = RANGE[q]
            base = "%s_%s" % (q, side)
            add(base + "_zero", q, side, 0.0)
            add(base + "_negzero", q, side, -0.0)
            # Values around chosen raw targets, off by fractions of an LSB on both sides.
            targets = [1, 2, 7, 100, 1000, hi // 3, hi - 1, hi]
            if q not in GAINS:
                targets += [-t for t in targets] + [lo]
            for t in targets:
                for frac in ("0", "0.25", "0.4999", "0.5001", "-0.25", "-0.4999", "-0.5001"):
                    f = Fraction(frac)
                    if (t == hi and f > Fraction(1, 2)) or (t == lo and f < -Fraction(1, 2)):
                        continue
                    si = float((t + f) / k)
                    add("%s_raw%d%s%s" % (base, t, "+" if f >= 0 else "", frac), q, side, si)
            # Just past either end of the range: errors naming the field.
            for over in ("0.5001", "0.6", "1", "100"):
                add("%s_over_hi_%s" % (base, over), q, side, float((hi + Fraction(over)) / k))
                if q not in GAINS:
                    add("%s_under_lo_%s" % (base, over), q, side,
                        float((lo - Fraction(over)) / k))
            add(base + "_huge", q, side, 1e300)
            add(base + "_inf", q, side, math.inf)
            add(base + "_nan", q, side, math.nan)
            if q in GAINS:
                add(base + "_neg_small", q, side, -1e-12)
                add(base + "_neg_one", q, side, -1.0)
                add(base + "_neg_inf", q, side, -math.inf)
            else:
                add(base + "_huge_neg", q, side, -1e300)
                add(base + "_neg_inf", q, side, -math.inf)
    # Exact half ties (dyadic inputs times an integer scale): halves go away from zero.
    for q, si in (("torque", 2.0 ** -12), ("kp", 2.0 ** -12), ("kd", 2.0 ** -14),
                  ("torque", 3 * 2.0 ** -12), ("kp", 2.0 ** -10)):
        add("%s_rotor_tie_pos_%s" % (q, repr(si)), q, "rotor", si)
        if q == "torque":
            add("%s_rotor_tie_neg_%s" % (q, repr(si)), q, "rotor", -si)
    # Typical control values.
    for name, q, side, si in (("typ_tau_out_10nm", "torque", "output", 10.0),
                              ("typ_tau_out_neg", "torque", "output", -25.5),
                              ("typ_speed_out_1rps", "speed", "output", 2 * math.pi),
                              ("typ_speed_rot_1000", "speed", "rotor", 1000.0),
                              ("typ_pos_out_90deg", "pos", "output", math.pi / 2),
                              ("typ_pos_out_neg_turn", "pos", "output", -2 * math.pi),
                              ("typ_pos_rot_1rad", "pos", "rotor", 1.0),
                              ("typ_kp_out_50", "kp", "output", 50.0),
                              ("typ_kd_out_2", "kd", "output", 2.0),
                              ("typ_kp_rot", "kp", "rotor", 0.001),
                              ("typ_kd_rot", "kd", "rotor", 0.0001)):
        add(name, q, side, si)
    rng = XorShift32(0x51C0FFEE)
    for i in range(200):
        q = QUANTITIES[rng.below(5)]
        side = ("rotor", "output")[rng.below(2)]
        lo, hi = RANGE[q]
        # Raw target uniformly over the range (and 5% beyond), plus a random fraction.
        span = hi - lo
        t = lo - span // 40 + (rng.u32() * (span + span // 20)) // 0xFFFFFFFF
        if q in GAINS:
            t = abs(t)
        f = Fraction(rng.below(1000) - 500, 1000)
        add("random_%03d" % i, q, side, float((t + f) / lsb_per_unit(q, side)))
    return out


def from_raw_vectors():
    """raw -> SI: the exact quotient, as the nearest double."""
    out = []
    for side in ("rotor", "output"):
        for q in QUANTITIES:
            lo, hi = RANGE[q]
            for raw in (lo, lo + 1, -1000, -1, 0, 1, 1000, hi - 1, hi):
                if q in GAINS and raw < 0:
                    continue
                out.append({"q": q, "side": side, "raw": raw,
                            "si": float(Fraction(raw) / lsb_per_unit(q, side))})
    for raw in (0, 1, 2048, 4096, 8191):
        out.append({"q": "out_pos", "side": "output", "raw": raw,
                    "si": float(Fraction(raw, 8192) * 2 * PI)})
    for raw in (0, 1, 48, 255):
        out.append({"q": "voltage", "side": "rotor", "raw": raw, "si": raw * 0.5})
    return out


def si_command_vectors():
    """Whole SI commands: fields -> frame, plain and saturating."""
    rows = []

    def add(name, side, ident, status, wd, tau, speed, pos, kp, kd):
        fields = {"torque": tau, "speed": speed, "pos": pos, "kp": kp, "kd": kd}
        results = {}
        for q in QUANTITIES:
            if not (robust(q, side, fields[q], EPS_DOUBLE) or
                    exact_in_binary(q, side, fields[q], False)):
                return
            results[q] = to_raw_exact(q, side, fields[q])
        expect = "ok"
        for q in QUANTITIES:  # the first failing field, in frame order, names the error
            if results[q][0] != "ok":
                expect = results[q][0]
                break
        raw = {q: results[q][1] for q in QUANTITIES}
        c = cmd(name, ident, status, wd, raw["torque"], raw["speed"], raw["pos"], raw["kp"],
                raw["kd"])
        if expect == "ok":
            expect = command_expect(c)
        hexs = pack_command(c).hex() if expect == "ok" else "-"
        # Saturating variant.
        if any(isinstance(fields[q], float) and math.isnan(fields[q]) for q in QUANTITIES):
            cexpect, mask, chex = "J288_ERR_NOT_FINITE", 0, "-"
        else:
            mask = 0
            craw = {}
            for bit, q in enumerate(QUANTITIES):
                was, r = clamp_exact(q, side, fields[q])
                craw[q] = r
                mask |= (1 << bit) if was else 0
            cc = cmd(name, ident, status, wd, craw["torque"], craw["speed"], craw["pos"],
                     craw["kp"], craw["kd"])
            cexpect = command_expect(cc)
            chex = pack_command(cc).hex() if cexpect == "ok" else "-"
        rows.append({"name": name, "side": side, "id": ident, "status": status, "wd": wd,
                     "si": [tau, speed, pos, kp, kd], "expect": expect, "hex": hexs,
                     "cexpect": cexpect, "mask": mask, "chex": chex})

    add("zero_rotor", "rotor", 0, 1, 1, 0.0, 0.0, 0.0, 0.0, 0.0)
    add("zero_output_lock", "output", 1, 0, 1, 0.0, 0.0, 0.0, 0.0, 0.0)
    add("hold_90deg_output", "output", 3, 1, 1, 0.0, 0.0, math.pi / 2, 50.0, 2.0)
    add("spin_output", "output", 4, 1, 0, 5.0, 2 * math.pi, 0.0, 0.0, 1.5)
    add("rotor_small", "rotor", 5, 1, 1, 0.01, 100.0, 12.5, 0.01, 0.0001)
    add("broadcast_output", "output", 15, 1, 0, -3.0, -1.0, -1.0, 10.0, 0.5)
    add("tau_too_big_output", "output", 6, 1, 1, 100.0, 0.0, 0.0, 0.0, 0.0)
    add("speed_too_big_rotor", "rotor", 6, 1, 1, 0.0, 1e6, 0.0, 0.0, 0.0)
    add("pos_too_big_output", "output", 6, 1, 1, 0.0, 0.0, 5000.0, 0.0, 0.0)
    add("kp_too_big_output", "output", 6, 1, 1, 0.0, 0.0, 0.0, 5000.0, 0.0)
    add("kd_too_big_output", "output", 6, 1, 1, 0.0, 0.0, 0.0, 0.0, 100.0)
    add("neg_kp_output", "output", 7, 1, 1, 0.0, 0.0, 0.0, -1.0, 0.0)
    add("neg_kd_rotor", "rotor", 7, 1, 1, 0.0, 0.0, 0.0, 0.0, -1e-6)
    add("nan_speed", "output", 8, 1, 1, 0.0, math.nan, 0.0, 0.0, 0.0)
    add("all_too_big_output", "output", 9, 1, 1, -1e9, 1e9, -1e9, 1e9, 1e9)
    add("neg_tau_and_neg_kd", "output", 10, 1, 1, -1000.0, 0.0, 0.0, 10.0, -1.0)
    add("inf_pos", "rotor", 11, 1, 1, 0.0, 0.0, math.inf, 0.0, 0.0)
    add("bad_status_si", "output", 12, 2, 1, 0.0, 0.0, 0.0, 0.0, 0.0)
    rng = XorShift32(0x5100C0DE)
    for i in range(40):
        side = ("rotor", "output")[rng.below(2)]
        vals = []
        for q in QUANTITIES:
            lo, hi = RANGE[q]
            t = rng.below(hi) * (1 if q in GAINS or rng.below(2) else -1)
            vals.append(float((t + Fraction(rng.below(1000) - 500, 1000)) / lsb_per_unit(q, side)))
        add("random_%02d" % i, side, rng.below(16), rng.below(2), rng.below(2), *vals)
    return rows


# ---------------------------------------------------------------------------------------------
# The joint core (j288/jointq.h): output-side commands from Q16 (torque, speed, gains) and
# Q24 (position, an int64) integers, and a reply's speed, torque and OutPos in Q16 / Q24.

Q16 = 1 << 16
Q24 = 1 << 24
FIXED_SCALE = {"torque": Q16, "speed": Q16, "pos": Q24, "kp": Q16, "kd": Q16}
# Factors that contain pi: the fixed path rounds them to within 2^-15 LSB of the exact value,
# so a vector whose exact value lies closer than this to a half is left out.
FIXED_PI_MARGIN = Fraction(1, 10**4)
# The position's reach: |pos| < 2^32 in Q24 (256 rad); beyond, J288_ERR_RANGE_POS (the header
# says so; the wire itself would reach 1428 rad).
FIXED_POS_REACH = 1 << 32


def fixed_to_raw(q, v):
    """(expect, raw) for one Q integer, exactly (output side)."""
    if q in GAINS and v < 0:
        return "J288_ERR_NEG_GAIN", 0
    if q == "pos" and abs(v) >= FIXED_POS_REACH:
        return RANGE_ERR[q], 0
    x = Fraction(v, FIXED_SCALE[q]) * lsb_per_unit(q, "output")
    lo, hi = RANGE[q]
    r = round_half_away(x)
    if r < lo or r > hi:
        return RANGE_ERR[q], 0
    return "ok", r


def fixed_near_half(q, v):
    if q not in ("speed", "pos"):
        return False  # rational factors: rounded exactly, ties included
    x = abs(Fraction(v, FIXED_SCALE[q]) * lsb_per_unit(q, "output"))
    return abs((x - math.floor(x)) - Fraction(1, 2)) < FIXED_PI_MARGIN


def fixed_command_vectors():
    rows = []

    def add(name, tau, speed, pos, kp, kd):
        vals = {"torque": tau, "speed": speed, "pos": pos, "kp": kp, "kd": kd}
        if any(fixed_near_half(q, vals[q]) for q in QUANTITIES):
            return
        res = {q: fixed_to_raw(q, vals[q]) for q in QUANTITIES}
        expect = next((res[q][0] for q in QUANTITIES if res[q][0] != "ok"), "ok")
        raw = [res[q][1] if expect == "ok" else 0 for q in QUANTITIES]
        mask, craw = 0, []
        for bit, q in enumerate(QUANTITIES):
            e, r = res[q]
            if e != "ok":
                mask |= 1 << bit
                lo, hi = RANGE[q]
                r = 0 if e == "J288_ERR_NEG_GAIN" else (lo if vals[q] < 0 else hi)
            craw.append(r)
        rows.append({"name": name, "q": [tau, speed, pos, kp, kd], "expect": expect,
                     "raw": raw, "mask": mask, "craw": craw})

    add("zero", 0, 0, 0, 0, 0)
    add("hold_90deg", 0, 0, round(math.pi / 2 * Q24), 50 * Q16, 2 * Q16)
    add("spin", 5 * Q16, round(2 * math.pi * Q16), 0, 0, 3 * Q16 // 2)
    add("negative", -3 * Q16, -Q16, -Q24, 10 * Q16, Q16 // 2)
    add("tau_tie", 23068, 0, 0, 0, 0)          # 312.5 LSB exactly: away from zero
    add("tau_tie_neg", -23068, 0, 0, 0, 0)
    add("kp_tie", 0, 0, 0, 33258289, 0)         # 7812.5 LSB exactly
    add("tau_max", 2418780, 0, 0, 0, 0)         # 32767.4 LSB
    add("tau_over", 2418830, 0, 0, 0, 0)        # 32768.1 LSB
    add("tau_min", -2418830, 0, 0, 0, 0)        # -32768.1: rounds to -32768, in range
    add("tau_under", -2418900, 0, 0, 0, 0)      # -32769.0
    add("speed_over", 0, 20000000, 0, 0, 0)
    add("kp_over", 0, 0, 0, 140000000, 0)
    add("kd_over", 0, 0, 0, 0, 1400000)
    add("neg_kp", 0, 0, 0, -1, 0)
    add("neg_kd", 0, 0, 0, 0, -1)
    add("pos_extremes", 0, 0, (1 << 31) - 1, 0, 0)
    add("pos_min", 0, 0, -(1 << 31), 0, 0)
    add("pos_128rad", 0, 0, 1 << 31, 0, 0)          # beyond the int32 Q24 of before
    add("pos_reach", 0, 0, (1 << 32) - 1, 0, 0)      # 256 rad less one step: in reach
    add("pos_beyond_reach", 0, 0, 1 << 32, 0, 0)     # 256 rad: J288_ERR_RANGE_POS
    add("pos_beyond_reach_neg", 0, 0, -(1 << 32), 0, 0)
    add("pos_far", 0, 0, 1 << 40, 0, 0)
    add("pos_far_kp_bad", 0, 0, -(1 << 40), -1, 0)   # the position's error comes first
    add("all_out", -(1 << 31), (1 << 31) - 1, -(1 << 31), (1 << 31) - 1, (1 << 31) - 1)
    add("all_out_neg_gains", (1 << 31) - 1, -(1 << 31), 0, -(1 << 31), -5)
    # The inputs closest to a half without being one, both sides, for the rational factors
    # (torque and gains): x = m num / den has 2 m num = den + t (mod 2 den) for a small t.
    for q, pos_in in (("torque", 0), ("kp", 3), ("kd", 4)):
        f = lsb_per_unit(q, "output") / FIXED_SCALE[q]
        num, den = f.numerator, f.denominator
        g = math.gcd(2 * num, 2 * den)
        lo, hi = RANGE[q]
        for t in (-2 * g, -g, g, 2 * g):
            if (den + t) % g:
                continue
            m = ((den + t) // g) * pow(2 * num // g, -1, 2 * den // g) % (2 * den // g)
            while m * f < hi - 1:
                vals = [0, 0, 0, 0, 0]
                vals[pos_in] = m
                add("%s_near_half_%+d_%d" % (q, t, m), *vals)
                m += 2 * den // g * max(1, (hi // 3) // max(1, int((2 * den // g) * f)))
    rng = XorShift32(0xF1CED0)
    for i in range(60):
        vals = []
        for q in QUANTITIES:
            lo, hi = RANGE[q]
            if q == "pos":
                vals.append(rng.signed(32))
                continue
            # around a random raw value, sometimes out of range
            t = Fraction(rng.below(hi + 2000), 1) + Fraction(rng.below(1000), 1000)
            if q not in GAINS and rng.below(2):
                t = -t
            if q in GAINS and rng.below(16) == 0:
                t = -t
            vals.append(round_half_away(t / lsb_per_unit(q, "output") * FIXED_SCALE[q]))
        add("random_%02d" % i, *vals)
    return rows


def fixed_reply_vectors():
    """Raw speed, torque, OutPos -> Q16 speed, Q16 torque, Q24 count centre (exact)."""
    rows = []
    rng = XorShift32(0xF1CEDB)
    picks = [(0, 0, 0), (1, 1, 1), (-1, -1, 8191), (32767, 32767, 4095), (-32768, -32768, 4096)]
    picks += [(rng.signed(16), rng.signed(16), rng.below(8192)) for _ in range(40)]
    for sp, tq, op in picks:
        speed = round_half_away(Fraction(sp) / lsb_per_unit("speed", "output") * Q16)
        torque = round_half_away(Fraction(tq) / lsb_per_unit("torque", "output") * Q16)
        enc = round_half_away((Fraction(op) + Fraction(1, 2)) * 2 * PI / 8192 * Q24)
        rows.append({"speed_raw": sp, "torque_raw": tq, "out_pos": op, "speed": speed,
                     "torque": torque, "encoder": enc})
    return rows


# ---------------------------------------------------------------------------------------------
# Output.


def check_spec_frames(cmds, replies):
    """The spec's worked frames, byte for byte: the generator must reproduce them."""
    # Copied from the protocol description's "Worked frames".
    want = {
        "spec_lock_id0": "fe ee 80 00 00 00 00 00 00 00 00 00 00 00 00 00 1d 99 fb 6e",
        "spec_foc_id3": "fe ee 93 00 00 00 00 00 5f 14 00 00 00 05 00 32 a6 4b 30 3f",
    }
    want = {k: v.replace(" ", "") for k, v in want.items()}
    want_reply = ("fc ee 13 24 29 30 00 05 d7 ff 5f 14 00 00 00 00 00 00 e8 03 00 00 49 c2 3b "
                  "ee").replace(" ", "")
    got = {c["name"]: pack_command(c).hex() for c in cmds}
    for name, hexs in want.items():
        if got[name] != hexs:
            raise AssertionError("worked frame %s: got %s want %s" % (name, got[name], hexs))
    r = [pack_reply(x).hex() for x in replies if x["name"] == "spec_reply_id3"][0]
    if r != want_reply:
        raise AssertionError("worked reply: got %s want %s" % (r, want_reply))
    if crc_mpeg2_bytes(b"123456789") != 0x0376E6E7:
        raise AssertionError("CRC-32/MPEG-2 check value")


HEADER_NOTE = "generated by tools/vectors/gen_vectors.py; do not edit, run `make vectors`"


def fmt_real(x):
    """Text form of a double that reads back (strtod, float()) as the same double."""
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


def c_real(x):
    if math.isnan(x):
        return "NAN"
    if math.isinf(x):
        return "INFINITY" if x > 0 else "-INFINITY"
    return repr(x) if ("e" in repr(x) or "." in repr(x)) else repr(x) + ".0"


def c_bytes(b):
    return "{" + ", ".join("0x%02x" % x for x in b) + "}"


def c_err(e):
    return {"ok": "J288_OK", "decode_only": "GOLDEN_DECODE_ONLY"}.get(e, e)


def write_text(path, lines):
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines) + "\n")


def render(outdir):
    cmds = command_vectors()
    replies = reply_vectors()
    check_spec_frames(cmds, replies)
    sis = si_vectors()
    froms = from_raw_vectors()
    sicmds = si_command_vectors()
    names = [c["name"] for c in cmds]
    assert len(set(names)) == len(names), "duplicate command vector names"
    assert len({r["name"] for r in replies}) == len(replies), "duplicate reply names"
    assert len({s["name"] + s["q"] + s["side"] for s in sis}) == len(sis), "duplicate SI names"

    files = {}
    lines = ["# j288 golden command frames (host -> servo, 20 bytes); " + HEADER_NOTE,
             "# One vector per line, whitespace-separated:",
             "#   name id status watchdog tau speed pos kp kd reserved expect hex",
             "# Integers are the raw wire values. hex is the complete frame (40 lowercase hex",
             "# digits). Decoding hex must give the fields. expect is what an encoder answers for",
             "# the fields: ok (it produces exactly hex), an error code (it refuses: the frame",
             "# exists on the wire but must not be sent), or decode_only (reserved byte not 0:",
             "# encoders always send 0)."]
    for c in cmds:
        c["hex"] = pack_command(c).hex()
        c["expect"] = command_expect(c)
        lines.append("%s %d %d %d %d %d %d %d %d %d %s %s" % (
            c["name"], c["id"], c["status"], c["watchdog"], c["tau"], c["speed"], c["pos"],
            c["kp"], c["kd"], c["reserved"], c["expect"], c["hex"]))
    files["commands.txt"] = lines

    lines = ["# j288 golden reply frames (servo -> host, 26 bytes); " + HEADER_NOTE,
             "# One vector per line, whitespace-separated:",
             "#   name id status watchdog case_temp winding_temp voltage_raw torque speed pos",
             "#   faults out_pos warnings reserved expect hex",
             "# faults is hexadecimal (0x...), everything else decimal; watchdog is the timeout",
             "# bit (1 = tripped). hex is the complete frame (52 lowercase hex digits); decoding",
             "# it must give the fields. expect: ok (a device-side encoder produces exactly hex)",
             "# or the error an encoder answers (id 15: no servo replies as broadcast)."]
    for r in replies:
        r["hex"] = pack_reply(r).hex()
        r["expect"] = reply_expect(r)
        lines.append("%s %d %d %d %d %d %d %d %d %d 0x%08x %d %d %d %s %s" % (
            r["name"], r["id"], r["status"], r["watchdog"], r["case_temp"], r["winding_temp"],
            r["voltage"], r["torque"], r["speed"], r["pos"], r["faults"], r["out_pos"],
            r["warnings"], r["reserved"], r["expect"], r["hex"]))
    files["replies.txt"] = lines

    lines = ["# j288 SI-unit conversion vectors; " + HEADER_NOTE,
             "# Lines starting with to_raw:   to_raw name quantity side si expect raw float_exact",
             "#   SI value (a double, printed so that it reads back exactly) -> raw integer,",
             "#   rounded to nearest with halves away from zero, computed exactly; expect is ok",
             "#   or the error code. float_exact 1: a single-precision build must give the same",
             "#   answer too (0: the value is too close to a rounding or range edge for float).",
             "# Lines starting with from_raw: from_raw quantity side raw si",
             "#   raw -> SI as the nearest double to the exact quotient.",
             "# quantity: torque (N*m), speed (rad/s), pos (rad), kp (N*m/rad), kd (N*m*s/rad),",
             "#   out_pos (output encoder counts -> rad), voltage (0.5 V per LSB).",
             "# side: rotor (the wire's own side) or output (through the gear ratio 288.35)."]
    for s in sis:
        lines.append("to_raw %s %s %s %s %s %d %d" % (s["name"], s["q"], s["side"],
                                                      fmt_real(s["si"]), s["expect"], s["raw"],
                                                      s["float_exact"]))
    for s in froms:
        lines.append("from_raw %s %s %d %s" % (s["q"], s["side"], s["raw"], fmt_real(s["si"])))
    files["si.txt"] = lines

    lines = ["# j288 SI commands -> frames; " + HEADER_NOTE,
             "# One vector per line, whitespace-separated:",
             "#   name side id status watchdog tau speed pos kp kd expect hex clamp_expect",
             "#   clamp_mask clamp_hex",
             "# SI fields (N*m, rad/s, rad, N*m/rad, N*m*s/rad) on the given side. expect/hex:",
             "# the plain conversion then encoding (the first failing field in frame order",
             "# names the error; hex is - on error). clamp_*: the saturating variant; clamp_mask",
             "# bits tau=1 speed=2 pos=4 kp=8 kd=16 say which fields were saturated."]
    for r in sicmds:
        lines.append("%s %s %d %d %d %s %s %s %s %s %s %s %s %d %s" % (
            r["name"], r["side"], r["id"], r["status"], r["wd"],
            fmt_real(r["si"][0]), fmt_real(r["si"][1]), fmt_real(r["si"][2]),
            fmt_real(r["si"][3]), fmt_real(r["si"][4]), r["expect"], r["hex"], r["cexpect"], r["mask"], r["chex"]))
    files["si_commands.txt"] = lines

    fxc = fixed_command_vectors()
    fxr = fixed_reply_vectors()
    lines = ["# j288 joint core conversions (j288/jointq.h); " + HEADER_NOTE,
             "# Lines starting with cmd: cmd name tau speed pos kp kd expect raw_tau raw_speed",
             "#   raw_pos raw_kp raw_kd clamp_mask c_tau c_speed c_pos c_kp c_kd",
             "#   Output side. Inputs are integers: tau, speed, kp, kd in Q16 (value * 2^16),",
             "#   pos in Q24 (rad * 2^24, beyond 2^32 out of reach). expect: ok or the first",
             "#   failing field's error in",
             "#   frame order; raw_*: the rounded fields (0 on error); c_*: the saturating",
             "#   variant, clamp_mask bits tau=1 speed=2 pos=4 kp=8 kd=16. Speed and position",
             "#   vectors whose exact value lies within 1e-4 LSB of a half are left out (their",
             "#   factors contain pi; the C code rounds them to within 2^-15 LSB).",
             "# Lines starting with reply: reply speed_raw torque_raw out_pos speed_q16",
             "#   torque_q16 encoder_q24 (exact, rounded half away from zero; the encoder is",
             "#   the centre of the OutPos count)."]
    for r in fxc:
        lines.append("cmd %s %s %s %s %d %s" % (
            r["name"], " ".join(str(x) for x in r["q"]), r["expect"],
            " ".join(str(x) for x in r["raw"]), r["mask"], " ".join(str(x) for x in r["craw"])))
    for r in fxr:
        lines.append("reply %d %d %d %d %d %d" % (r["speed_raw"], r["torque_raw"], r["out_pos"],
                                                 r["speed"], r["torque"], r["encoder"]))
    files["fixed.txt"] = lines

    files["golden_vectors.h"] = render_header(cmds, replies, sis, froms, sicmds, fxc, fxr)

    os.makedirs(outdir, exist_ok=True)
    for name, content in files.items():
        write_text(os.path.join(outdir, name), content)
    return {k: len(v) for k, v in (("commands", cmds), ("replies", replies), ("si", sis),
                                   ("from_raw", froms), ("si_commands", sicmds),
                                   ("fixed commands", fxc), ("fixed replies", fxr))}


def render_header(cmds, replies, sis, froms, sicmds, fxc, fxr):
    q_enum = {"torque": "GOLDEN_Q_TORQUE", "speed": "GOLDEN_Q_SPEED", "pos": "GOLDEN_Q_POS",
              "kp": "GOLDEN_Q_KP", "kd": "GOLDEN_Q_KD", "out_pos": "GOLDEN_Q_OUT_POS",
              "voltage": "GOLDEN_Q_VOLTAGE"}
    side_enum = {"rotor": "0", "output": "1"}
    h = ["/* " + HEADER_NOTE + ".",
         " *",
         " * Golden frames and SI conversions from the independent Python generator, for unit",
         " * tests on hosts and on targets without a file system. The same vectors are in",
         " * commands.txt, replies.txt, si.txt, si_commands.txt and fixed.txt beside this file.",
         " *",
         " * Tables are static; define before including the tables you use (an unused static",
         " * table would warn): GOLDEN_WANT_COMMANDS, GOLDEN_WANT_REPLIES, GOLDEN_WANT_SI,",
         " * GOLDEN_WANT_SI_COMMANDS, GOLDEN_WANT_FIXED, GOLDEN_WANT_NAMES. Needs j288/error.h for",
         " * the codes and",
         " * math.h (NAN, INFINITY) for the SI tables.",
         " */",
         "#ifndef J288_GOLDEN_VECTORS_H",
         "#define J288_GOLDEN_VECTORS_H",
         "",
         "#include <stdint.h>",
         "",
         "#include \"j288/error.h\"",
         "",
         "/* Encoder accepts the fields but sends another frame (reserved byte forced to 0). */",
         "#define GOLDEN_DECODE_ONLY 1",
         "",
         "enum { GOLDEN_Q_TORQUE = 0, GOLDEN_Q_SPEED, GOLDEN_Q_POS, GOLDEN_Q_KP, GOLDEN_Q_KD,",
         "       GOLDEN_Q_OUT_POS, GOLDEN_Q_VOLTAGE };",
         "",
         "typedef struct {",
         "    const char *name;",
         "    uint8_t id, status, watchdog, reserved;",
         "    int16_t tau, speed;",
         "    int32_t pos;",
         "    int16_t kp, kd;",
         "    int expect; /* J288_OK, an encoder error, or GOLDEN_DECODE_ONLY */",
         "    uint8_t frame[20];",
         "} golden_cmd_t;",
         "",
         "typedef struct {",
         "    const char *name;",
         "    uint8_t id, status, watchdog;",
         "    int8_t case_temp;",
         "    uint8_t winding_temp, voltage_raw;",
         "    int16_t torque, speed;",
         "    int32_t pos;",
         "    uint32_t faults;",
         "    uint16_t out_pos;",
         "    uint8_t warnings;",
         "    uint16_t reserved;",
         "    int expect; /* J288_OK or the device-side encoder's error */",
         "    uint8_t frame[26];",
         "} golden_reply_t;",
         "",
         "typedef struct {",
         "    const char *name;",
         "    uint8_t quantity; /* GOLDEN_Q_* */",
         "    uint8_t side;     /* 0 rotor, 1 output (j288_side_t values) */",
         "    double si;",
         "    int expect;       /* J288_OK or the error code */",
         "    int32_t raw;      /* when expect is J288_OK */",
         "    uint8_t float_exact; /* 1: a float build must agree exactly as well */",
         "} golden_si_t;",
         "",
         "typedef struct {",
         "    uint8_t quantity;",
         "    uint8_t side;",
         "    int32_t raw;",
         "    double si; /* nearest double to the exact quotient */",
         "} golden_from_raw_t;",
         "",
         "typedef struct {",
         "    const char *name;",
         "    uint8_t side, id, status, watchdog;",
         "    double tau, speed, pos, kp, kd;",
         "    int expect;      /* j288_cmd_encode_si() result */",
         "    uint8_t frame[20];   /* when expect is J288_OK */",
         "    int clamp_expect;    /* from_si_clamped + encode result */",
         "    unsigned clamp_mask; /* J288_FIELD_* bits */",
         "    uint8_t clamp_frame[20];",
         "} golden_si_cmd_t;",
         ""]
    h += ["typedef struct {",
          "    const char *name;",
          "    int64_t q[5];      /* tau, speed, kp, kd in Q16; pos in Q24 */",
          "    int expect;        /* j288_cmd_from_q() result */",
          "    int32_t raw[5];    /* tau, speed, pos, kp, kd when expect is J288_OK */",
          "    unsigned clamp_mask;",
          "    int32_t craw[5];   /* j288_cmd_from_q_clamped() */",
          "} golden_fixed_cmd_t;",
          "",
          "typedef struct {",
          "    int16_t speed_raw, torque_raw;",
          "    uint16_t out_pos;",
          "    int32_t speed, torque; /* Q16, exact */",
          "    int32_t encoder;       /* Q24, exact */",
          "} golden_fixed_reply_t;",
          ""]
    h += ["#define GOLDEN_CMD_COUNT %du" % len(cmds),
          "#define GOLDEN_REPLY_COUNT %du" % len(replies),
          "#define GOLDEN_SI_COUNT %du" % len(sis),
          "#define GOLDEN_FROM_RAW_COUNT %du" % len(froms),
          "#define GOLDEN_SI_CMD_COUNT %du" % len(sicmds),
          "#define GOLDEN_FIXED_CMD_COUNT %du" % len(fxc),
          "#define GOLDEN_FIXED_REPLY_COUNT %du" % len(fxr),
          "#define GOLDEN_FAULT_NAME_COUNT %du" % len(FAULT_NAMES),
          ""]
    h += ["#ifdef GOLDEN_WANT_COMMANDS",
          "static const golden_cmd_t golden_cmds[GOLDEN_CMD_COUNT] = {"]
    for c in cmds:
        h.append("    {\"%s\", %d, %d, %d, %d, %d, %d, %s, %d, %d, %s,\n     %s}," % (
            c["name"], c["id"], c["status"], c["watchdog"], c["reserved"], c["tau"],
            c["speed"], c["pos"] if c["pos"] != INT32[0] else "INT32_MIN", c["kp"], c["kd"],
            c_err(c["expect"]), c_bytes(pack_command(c))))
    h += ["};", "#endif", ""]
    h += ["#ifdef GOLDEN_WANT_REPLIES",
          "static const golden_reply_t golden_replies[GOLDEN_REPLY_COUNT] = {"]
    for r in replies:
        h.append("    {\"%s\", %d, %d, %d, %d, %d, %d, %d, %d, %s, 0x%08xu, %d, %d, %d, %s,\n"
                 "     %s}," % (
                     r["name"], r["id"], r["status"], r["watchdog"], r["case_temp"],
                     r["winding_temp"], r["voltage"], r["torque"], r["speed"],
                     r["pos"] if r["pos"] != INT32[0] else "INT32_MIN", r["faults"],
                     r["out_pos"], r["warnings"], r["reserved"], c_err(r["expect"]),
                     c_bytes(pack_reply(r))))
    h += ["};", "#endif", ""]
    h += ["#ifdef GOLDEN_WANT_SI",
          "static const golden_si_t golden_si[GOLDEN_SI_COUNT] = {"]
    for s in sis:
        raw = s["raw"]
        h.append("    {\"%s\", %s, %s, %s, %s, %s, %d}," % (
            s["name"], q_enum[s["q"]], side_enum[s["side"]], c_real(s["si"]),
            c_err(s["expect"]), str(raw) if raw != INT32[0] else "INT32_MIN",
            s["float_exact"]))
    h += ["};", "",
          "static const golden_from_raw_t golden_from_raw[GOLDEN_FROM_RAW_COUNT] = {"]
    for s in froms:
        h.append("    {%s, %s, %s, %s}," % (q_enum[s["q"]], side_enum[s["side"]],
                                            str(s["raw"]) if s["raw"] != INT32[0]
                                            else "INT32_MIN", c_real(s["si"])))
    h += ["};", "#endif", ""]
    h += ["#ifdef GOLDEN_WANT_SI_COMMANDS",
          "static const golden_si_cmd_t golden_si_cmds[GOLDEN_SI_CMD_COUNT] = {"]
    for r in sicmds:
        frame = bytes.fromhex(r["hex"]) if r["hex"] != "-" else bytes(20)
        cframe = bytes.fromhex(r["chex"]) if r["chex"] != "-" else bytes(20)
        h.append("    {\"%s\", %s, %d, %d, %d, %s, %s, %s,\n     %s, %s, %s,\n     %s,\n"
                 "     %s, %du,\n     %s}," % (
                     r["name"], side_enum[r["side"]], r["id"], r["status"], r["wd"],
                     *[c_real(x) for x in r["si"]], c_err(r["expect"]), c_bytes(frame),
                     c_err(r["cexpect"]), r["mask"], c_bytes(cframe)))
    h += ["};", "#endif", ""]
    def c_i32(x):
        return str(x) if x != INT32[0] else "INT32_MIN"

    h += ["#ifdef GOLDEN_WANT_FIXED",
          "static const golden_fixed_cmd_t golden_fixed_cmds[GOLDEN_FIXED_CMD_COUNT] = {"]
    for r in fxc:
        h.append("    {\"%s\", {%s}, %s,\n     {%s}, %du, {%s}}," % (
            r["name"], ", ".join(c_i32(x) for x in r["q"]), c_err(r["expect"]),
            ", ".join(c_i32(x) for x in r["raw"]), r["mask"],
            ", ".join(c_i32(x) for x in r["craw"])))
    h += ["};", "",
          "static const golden_fixed_reply_t golden_fixed_replies[GOLDEN_FIXED_REPLY_COUNT] = {"]
    for r in fxr:
        h.append("    {%d, %d, %du, %d, %d, %d}," % (r["speed_raw"], r["torque_raw"], r["out_pos"],
                                                    r["speed"], r["torque"], r["encoder"]))
    h += ["};", "#endif", ""]
    h += ["#ifdef GOLDEN_WANT_NAMES",
          "static const char *const golden_fault_names[GOLDEN_FAULT_NAME_COUNT] = {"]
    h += ["    \"%s\"," % n for n in FAULT_NAMES]
    h += ["};", "static const char *const golden_warning_names[3] = {"]
    h += ["    \"%s\"," % n for n in WARNING_NAMES]
    h += ["};", "#endif", "", "#endif /* J288_GOLDEN_VECTORS_H */"]
    return h


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("test", "vectors"),
                    help="output folder (default test/vectors)")
    args = ap.parse_args(argv)
    counts = render(args.out)
    print("vectors: " + ", ".join("%d %s" % (n, k) for k, n in counts.items()) +
          " -> " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
