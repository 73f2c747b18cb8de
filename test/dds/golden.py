#!/usr/bin/env python3
"""The bytes Cyclone DDS should put on the wire for test/dds/dds_golden.c's samples, computed
here from the rules alone (nothing of the bridge, of Cyclone or of idlc's output is used):

XCDR1 (OMG DDS-XTypes 1.3, 7.4.1 "plain CDR", as ROS 2 and unitree_sdk2 use it):
- a 4-byte encapsulation header: representation id 0x0001 (CDR, little endian), then 2 bytes of
  options whose two low bits count the padding bytes added at the end so that the whole
  serialized size is a multiple of 4 (7.6.3.1.2);
- the body: each primitive aligned to its own size (1, 2, 4, 8), relative to the body's
  start; structs have no alignment or padding of their own, members follow in order;
- a string is a uint32 length counting the terminating NUL, the bytes, the NUL;
- a sequence is a uint32 element count, then the elements; an array just the elements.

The unitree crc (unitree_sdk2): the message copied into a C struct (natural alignment, zero
padding), crc32_core over its 32-bit little-endian words but the last: polynomial 0x04C11DB7,
initial 0xFFFFFFFF, each word shifted in most significant bit first, no final XOR.

unitree_hg (the humanoids) the same way: LowCmd 1004 bytes, LowState 2092.

Prints `name hex` lines in dds_golden's order (and the crc of a LowState sample and of
unitree_hg's LowCmd and LowState samples, which only the crc test uses). The samples must match
dds_golden.c's."""
import struct


class Cdr:
    def __init__(self):
        self.b = bytearray()

    def align(self, n):
        while len(self.b) % n:
            self.b.append(0)

    def prim(self, fmt, v):
        size = struct.calcsize('<' + fmt)
        self.align(size)
        self.b += struct.pack('<' + fmt, v)

    def string(self, s):
        data = s.encode() + b'\0'
        self.prim('I', len(data))
        self.b += data

    def seq(self, fmt, values):
        self.prim('I', len(values))
        for v in values:
            self.prim(fmt, v)

    def wire(self):
        pad = (4 - len(self.b) % 4) % 4
        return bytes([0x00, 0x01, 0x00, pad]) + bytes(self.b) + bytes(pad)


def header(c, sec, nanosec, frame_id):
    c.prim('i', sec)
    c.prim('I', nanosec)
    c.string(frame_id)


def joint_state():
    c = Cdr()
    header(c, 1700000000, 123456789, 'base')
    c.prim('I', 2)
    c.string('hip')
    c.string('knee')
    c.seq('d', [0.5, -1.25])   # position
    c.seq('d', [])             # velocity: empty
    c.seq('d', [2.0, 0.0])     # effort
    return c.wire()


# The LowCmd sample, member by member: (format, value) in order.
def lowcmd_fields(crc):
    f = [('B', 0xFE), ('B', 0xEF), ('B', 0xFF), ('B', 0), ('I', 1), ('I', 2), ('I', 3), ('I', 4),
         ('H', 0x1234)]
    for i in range(20):
        f += [('B', 1 if i < 3 else 0), ('f', 0.25 * i), ('f', -0.5 * i), ('f', 1.0), ('f', 20.0),
              ('f', 0.75), ('I', i), ('I', 0), ('I', 0)]
    f += [('B', 0xA5), ('B', 1), ('B', 2), ('B', 3)]
    f += [('B', k) for k in range(40)] + [('B', 0x10 + k) for k in range(12)]
    f += [('B', 7), ('B', 8), ('B', 9), ('I', 0xDEADBEEF), ('I', crc)]
    return f


def crc32_core(words):
    crc = 0xFFFFFFFF
    for w in words:
        for bit in range(31, -1, -1):
            top = crc & 0x80000000
            crc = (crc << 1) & 0xFFFFFFFF
            if top:
                crc ^= 0x04C11DB7
            if (w >> bit) & 1:
                crc ^= 0x04C11DB7
    return crc


def lowcmd_crc():
    # unitree's C struct LowCmd: MotorCmd (mode + 5 floats + 3 uint32) is 4-aligned, 36 bytes;
    # the struct is 812 bytes. '<' with explicit 'x' pads spells out the natural layout.
    fmt = '<4B4IH2x' + 'B3x5f3I' * 20 + '4B' + '55Bx' + '2I'
    vals = [v for _, v in lowcmd_fields(0)]
    raw = struct.pack(fmt, *vals)
    assert len(raw) == 812
    words = struct.unpack('<%dI' % (len(raw) // 4), raw)[:-1]
    return crc32_core(words)


# The LowState sample (the same in dds_golden.c): unitree's C struct LowState, 1180 bytes.
LOWSTATE_FMT = ('<4B4IH2x' + '13fB3x' + 'B3x7fB3x3I' * 20 + '4BiH4B15H'
                + '8hI40BB3xfBB2x2f4H2I')


def lowstate_values():
    v = [0xFE, 0xEF, 0xFF, 0, 5, 6, 7, 8, 0x4321]
    v += [1.0, 0.0, 0.0, 0.0, 0.5, -0.5, 0.25, 0.0, 0.0, 9.75, 0.125, -0.125, 3.0, 249]
    for i in range(20):
        v += [i % 2, 0.5 * i, -0.25 * i, 0.0, 1.5, 0.0, 0.0, 0.0, 30 + i, i * 3, 0, 0]
    v += [1, 2, 3, 80, -1500, 42, 253, 4, 5, 250] + [3700 + k for k in range(15)]
    v += [10, -20, 30, -40, 1, 2, 3, 4, 123456] + [k for k in range(40)]
    v += [0x5A, 0.75, 33, 34, 24.5, -1.25, 100, 200, 300, 400, 0xCAFEF00D, 0]
    return v


def lowstate_crc():
    raw = struct.pack(LOWSTATE_FMT, *lowstate_values())
    assert len(raw) == 1180
    return crc32_core(struct.unpack('<295I', raw)[:-1])


# unitree_hg's C structs: MotorCmd (mode, 5 floats, uint32) 28 bytes; MotorState (mode, 4 floats,
# int16[2], float, uint32[2], uint32, uint32[4]) 56; IMUState (13 floats, int16) 56.
HG_LOWCMD_FMT = '<BB2x' + 'B3x5fI' * 35 + '4I' + 'I'
HG_LOWSTATE_FMT = '<2IBB2xI' + '13fh2x' + 'B3x4f2hf2II4I' * 35 + '40B' + '4I' + 'I'


def hg_lowcmd_crc():
    v = [1, 6]
    for i in range(35):
        v += [1 if i % 3 == 0 else 0, 0.125 * i, -0.25 * i, 0.5, 40.0, 1.5, 100 + i]
    v += [0x01010101 * (k + 1) for k in range(4)] + [0]
    raw = struct.pack(HG_LOWCMD_FMT, *v)
    assert len(raw) == 1004
    return crc32_core(struct.unpack('<251I', raw)[:-1])


def hg_lowstate_crc():
    v = [1, 2, 0, 5, 987654]
    v += [1.0, 0.0, 0.0, 0.0, 0.5, -0.5, 0.25, 0.0, 0.0, 9.75, 0.125, -0.125, 3.0, -7]
    for i in range(35):
        v += [i % 2, 0.5 * i, -0.25 * i, 0.0625, 1.5, 30 + i, -5 - i, 24.25, i, 7 * i,
              0x20 if i == 3 else 0, 0, 0, 0, 0xFFFFFFFF - i]
    v += [200 + k for k in range(40)] + [0xCAFEF00D, 0, 0, 0] + [0]
    raw = struct.pack(HG_LOWSTATE_FMT, *v)
    assert len(raw) == 2092
    return crc32_core(struct.unpack('<523I', raw)[:-1])


def lowcmd(crc):
    c = Cdr()
    for fmt, v in lowcmd_fields(crc):
        c.prim(fmt, v)
    return c.wire()


def header_only():
    c = Cdr()
    header(c, -2, 7, 'ab')
    return c.wire()


if __name__ == '__main__':
    crc = lowcmd_crc()
    print('lowcmd_crc %08x' % crc)
    print('lowstate_crc %08x' % lowstate_crc())
    print('hg_lowcmd_crc %08x' % hg_lowcmd_crc())
    print('hg_lowstate_crc %08x' % hg_lowstate_crc())
    print('joint_state ' + joint_state().hex())
    print('lowcmd ' + lowcmd(crc).hex())
    print('header ' + header_only().hex())
