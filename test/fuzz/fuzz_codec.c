/*
 * Fuzz target: the frame codec (both directions), the CRC backends and the name tables.
 *
 * Input: byte 0 chooses the case (low 3 bits) and flags (bit 6: force the right head,
 * bit 7: force the right CRC, so that the accepting paths are reached often; bits 3-4: CRC
 * engine); the rest is the case's bytes (zeros once they run out).
 *
 * Invariants:
 * - reply/command decode: J288_OK exactly when the head is right and the CRC (computed by an
 *   independent bitwise reference) matches; otherwise BAD_HEADER before CRC, and the output
 *   struct untouched. Every decoded field equals the bytes read independently; re-encoding a
 *   decoded frame gives back the same bytes (a command's reserved byte aside, which encoders
 *   send as 0), or the documented error with the output buffer untouched.
 * - command/reply encode from arbitrary field values: the documented error for the first bad
 *   field, output untouched; otherwise a frame the reference accepts whose fields read back.
 * - CRC: table, nibble and bitwise backends, in any split of the stream, and the MPEG-2 byte
 *   form over reversed groups, all equal the reference.
 */
#include "fuzz_common.h"

#include "j288/crc32.h"
#include "j288/error.h"
#include "j288/frame.h"

#include <string.h>

static int crc_ctx_tag; /* the engine's ctx must reach its fn unchanged */

static uint32_t crc_fn_nibble(void *ctx, const uint8_t *d, size_t n)
{
    FUZZ_CHECK(ctx == (void *)&crc_ctx_tag);
    return j288_crc32_update_nibble(J288_CRC32_INIT, d, n);
}

static const j288_crc_t *pick_crc(uint8_t flags, j288_crc_t *engine)
{
    switch ((flags >> 3) & 3u) {
    case 1u:
        engine->fn = crc_fn_nibble;
        engine->ctx = &crc_ctx_tag;
        return engine;
    case 2u:
        engine->fn = NULL; /* an engine without fn: the default backend */
        engine->ctx = NULL;
        return engine;
    default:
        return NULL;
    }
}

static void check_reply_fields(const uint8_t *f, const j288_reply_raw_t *r)
{
    uint16_t out = fuzz_le16(&f[18]);
    FUZZ_CHECK(r->id == (f[2] & 0x0Fu));
    FUZZ_CHECK(r->status == ((f[2] >> 4) & 7u));
    FUZZ_CHECK(r->watchdog_tripped == ((f[2] & 0x80u) != 0u));
    FUZZ_CHECK((int)r->case_temp_c == ((f[3] < 128u) ? (int)f[3] : (int)f[3] - 256));
    FUZZ_CHECK(r->winding_temp_c == f[4]);
    FUZZ_CHECK(r->voltage_raw == f[5]);
    FUZZ_CHECK((int32_t)r->torque == fuzz_s16(fuzz_le16(&f[6])));
    FUZZ_CHECK((int32_t)r->speed == fuzz_s16(fuzz_le16(&f[8])));
    FUZZ_CHECK((int64_t)r->pos == fuzz_s32(fuzz_le32(&f[10])));
    FUZZ_CHECK(r->faults == fuzz_le32(&f[14]));
    FUZZ_CHECK(r->out_pos == (out & 0x1FFFu));
    FUZZ_CHECK(r->warnings == (out >> 13));
    FUZZ_CHECK(r->reserved == fuzz_le16(&f[20]));
}

static void check_cmd_fields(const uint8_t *f, const j288_cmd_raw_t *c)
{
    FUZZ_CHECK(c->id == (f[2] & 0x0Fu));
    FUZZ_CHECK(c->status == ((f[2] >> 4) & 7u));
    FUZZ_CHECK(c->watchdog == ((f[2] & 0x80u) != 0u));
    FUZZ_CHECK(c->reserved == f[3]);
    FUZZ_CHECK((int32_t)c->tau == fuzz_s16(fuzz_le16(&f[4])));
    FUZZ_CHECK((int32_t)c->speed == fuzz_s16(fuzz_le16(&f[6])));
    FUZZ_CHECK((int64_t)c->pos == fuzz_s32(fuzz_le32(&f[8])));
    FUZZ_CHECK((int32_t)c->kp == fuzz_s16(fuzz_le16(&f[12])));
    FUZZ_CHECK((int32_t)c->kd == fuzz_s16(fuzz_le16(&f[14])));
}

static void fill(fuzz_in_t *in, uint8_t *buf, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        buf[i] = fuzz_u8(in);
    }
}

static void case_reply_decode(fuzz_in_t *in, uint8_t flags, const j288_crc_t *crc)
{
    uint8_t f[J288_REPLY_LEN], out[J288_REPLY_LEN], out_before[J288_REPLY_LEN];
    j288_reply_raw_t r, before, un;
    int rc, want;

    fill(in, f, sizeof f);
    if ((flags & 0x40u) != 0u) {
        f[0] = 0xFCu;
        f[1] = 0xEEu;
    }
    if ((flags & 0x80u) != 0u) {
        fuzz_put_le32(&f[22], fuzz_ref_crc(&f[2], 5u));
    }
    FUZZ_CHECK(j288_reply_crc_expected(f, crc) == fuzz_ref_crc(&f[2], 5u));
    FUZZ_CHECK(j288_frame_crc_field(f, J288_REPLY_LEN) == fuzz_le32(&f[22]));
    memset(&r, 0xA5, sizeof r);
    memcpy(&before, &r, sizeof r);
    rc = j288_reply_decode(f, &r, crc);
    if ((f[0] != 0xFCu) || (f[1] != 0xEEu)) {
        want = J288_ERR_BAD_HEADER;
    } else if (!fuzz_reply_valid(f)) {
        want = J288_ERR_CRC;
    } else {
        want = J288_OK;
    }
    FUZZ_CHECK(rc == want);
    if (rc != J288_OK) {
        FUZZ_CHECK(memcmp(&r, &before, sizeof r) == 0);
        return;
    }
    check_reply_fields(f, &r);
    j288_reply_unpack(f, &un);
    check_reply_fields(f, &un);
    memset(out, 0x5A, sizeof out);
    memcpy(out_before, out, sizeof out);
    rc = j288_reply_encode(&r, out, crc);
    if (r.id <= 14u) {
        FUZZ_CHECK(rc == J288_OK);
        FUZZ_CHECK(memcmp(out, f, sizeof f) == 0);
    } else {
        FUZZ_CHECK(rc == J288_ERR_BAD_ID);
        FUZZ_CHECK(memcmp(out, out_before, sizeof out) == 0);
    }
}

static void case_cmd_decode(fuzz_in_t *in, uint8_t flags, const j288_crc_t *crc)
{
    uint8_t f[J288_CMD_LEN], out[J288_CMD_LEN], out_before[J288_CMD_LEN], want_f[J288_CMD_LEN];
    j288_cmd_raw_t c, before, un;
    int rc, want;

    fill(in, f, sizeof f);
    if ((flags & 0x40u) != 0u) {
        f[0] = 0xFEu;
        f[1] = 0xEEu;
    }
    if ((flags & 0x80u) != 0u) {
        fuzz_put_le32(&f[16], fuzz_ref_crc(f, 4u));
    }
    FUZZ_CHECK(j288_cmd_crc_expected(f, crc) == fuzz_ref_crc(f, 4u));
    FUZZ_CHECK(j288_frame_crc_field(f, J288_CMD_LEN) == fuzz_le32(&f[16]));
    memset(&c, 0xA5, sizeof c);
    memcpy(&before, &c, sizeof c);
    rc = j288_cmd_decode(f, &c, crc);
    if ((f[0] != 0xFEu) || (f[1] != 0xEEu)) {
        want = J288_ERR_BAD_HEADER;
    } else if (!fuzz_cmd_valid(f)) {
        want = J288_ERR_CRC;
    } else {
        want = J288_OK;
    }
    FUZZ_CHECK(rc == want);
    if (rc != J288_OK) {
        FUZZ_CHECK(memcmp(&c, &before, sizeof c) == 0);
        return;
    }
    check_cmd_fields(f, &c);
    j288_cmd_unpack(f, &un);
    check_cmd_fields(f, &un);
    memset(out, 0x5A, sizeof out);
    memcpy(out_before, out, sizeof out);
    rc = j288_cmd_encode(&c, out, crc);
    if (c.status > 1u) {
        FUZZ_CHECK(rc == J288_ERR_BAD_STATUS);
    } else if ((c.kp < 0) || (c.kd < 0)) {
        FUZZ_CHECK(rc == J288_ERR_NEG_GAIN);
    } else {
        FUZZ_CHECK(rc == J288_OK);
        memcpy(want_f, f, sizeof f);
        want_f[3] = 0u; /* encoders always send the reserved byte as 0 */
        fuzz_put_le32(&want_f[16], fuzz_ref_crc(want_f, 4u));
        FUZZ_CHECK(memcmp(out, want_f, sizeof out) == 0);
        return;
    }
    FUZZ_CHECK(memcmp(out, out_before, sizeof out) == 0);
}

static void case_cmd_encode(fuzz_in_t *in, const j288_crc_t *crc)
{
    uint8_t out[J288_CMD_LEN], before[J288_CMD_LEN];
    j288_cmd_raw_t c, back;
    int rc, want;

    memset(&c, 0, sizeof c);
    c.id = (uint8_t)(fuzz_u8(in) % 20u); /* mostly near the valid range */
    c.status = (uint8_t)(fuzz_u8(in) % 10u);
    c.watchdog = (fuzz_u8(in) & 1u) != 0u;
    c.tau = (int16_t)fuzz_s16(fuzz_u16(in));
    c.speed = (int16_t)fuzz_s16(fuzz_u16(in));
    c.pos = (int32_t)fuzz_s32(fuzz_u32(in));
    c.kp = (int16_t)fuzz_s16(fuzz_u16(in));
    c.kd = (int16_t)fuzz_s16(fuzz_u16(in));
    c.reserved = fuzz_u8(in);
    memset(out, 0x77, sizeof out);
    memcpy(before, out, sizeof out);
    rc = j288_cmd_encode(&c, out, crc);
    if (c.id > 15u) {
        want = J288_ERR_BAD_ID;
    } else if (c.status > 1u) {
        want = J288_ERR_BAD_STATUS;
    } else if ((c.kp < 0) || (c.kd < 0)) {
        want = J288_ERR_NEG_GAIN;
    } else {
        want = J288_OK;
    }
    FUZZ_CHECK(rc == want);
    if (rc != J288_OK) {
        FUZZ_CHECK(memcmp(out, before, sizeof out) == 0);
        return;
    }
    FUZZ_CHECK(fuzz_cmd_valid(out));
    FUZZ_CHECK(out[3] == 0u);
    FUZZ_CHECK(j288_cmd_decode(out, &back, NULL) == J288_OK);
    check_cmd_fields(out, &back);
    FUZZ_CHECK(back.id == c.id && back.status == c.status && back.watchdog == c.watchdog);
    FUZZ_CHECK(back.tau == c.tau && back.speed == c.speed && back.pos == c.pos);
    FUZZ_CHECK(back.kp == c.kp && back.kd == c.kd && back.reserved == 0u);
}

static void case_reply_encode(fuzz_in_t *in, const j288_crc_t *crc)
{
    uint8_t out[J288_REPLY_LEN], before[J288_REPLY_LEN];
    j288_reply_raw_t r, back;
    int rc, want;
    uint8_t t;

    memset(&r, 0, sizeof r);
    r.id = (uint8_t)(fuzz_u8(in) % 20u);
    r.status = (uint8_t)(fuzz_u8(in) % 10u);
    r.watchdog_tripped = (fuzz_u8(in) & 1u) != 0u;
    t = fuzz_u8(in);
    r.case_temp_c = (int8_t)((t < 128u) ? (int)t : (int)t - 256);
    r.winding_temp_c = fuzz_u8(in);
    r.voltage_raw = fuzz_u8(in);
    r.torque = (int16_t)fuzz_s16(fuzz_u16(in));
    r.speed = (int16_t)fuzz_s16(fuzz_u16(in));
    r.pos = (int32_t)fuzz_s32(fuzz_u32(in));
    r.faults = fuzz_u32(in);
    r.out_pos = (uint16_t)(fuzz_u16(in) % 9000u);
    r.warnings = (uint8_t)(fuzz_u8(in) % 10u);
    r.reserved = fuzz_u16(in);
    memset(out, 0x77, sizeof out);
    memcpy(before, out, sizeof out);
    rc = j288_reply_encode(&r, out, crc);
    if (r.id > 14u) {
        want = J288_ERR_BAD_ID;
    } else if (r.status > 7u) {
        want = J288_ERR_BAD_STATUS;
    } else if ((r.out_pos > 8191u) || (r.warnings > 7u)) {
        want = J288_ERR_RANGE;
    } else {
        want = J288_OK;
    }
    FUZZ_CHECK(rc == want);
    if (rc != J288_OK) {
        FUZZ_CHECK(memcmp(out, before, sizeof out) == 0);
        return;
    }
    FUZZ_CHECK(fuzz_reply_valid(out));
    FUZZ_CHECK(j288_reply_decode(out, &back, NULL) == J288_OK);
    check_reply_fields(out, &back);
    FUZZ_CHECK(back.id == r.id && back.status == r.status);
    FUZZ_CHECK(back.watchdog_tripped == r.watchdog_tripped);
    FUZZ_CHECK(back.case_temp_c == r.case_temp_c && back.winding_temp_c == r.winding_temp_c);
    FUZZ_CHECK(back.voltage_raw == r.voltage_raw && back.torque == r.torque);
    FUZZ_CHECK(back.speed == r.speed && back.pos == r.pos && back.faults == r.faults);
    FUZZ_CHECK(back.out_pos == r.out_pos && back.warnings == r.warnings);
    FUZZ_CHECK(back.reserved == r.reserved);
}

static void case_crc(fuzz_in_t *in)
{
    uint8_t buf[256], rev[256];
    size_t split, nwords, i;
    uint32_t want, a, b, c;
    int err;
    unsigned bit;

    split = fuzz_u8(in);
    nwords = in->n / 4u;
    if (nwords > sizeof buf / 4u) {
        nwords = sizeof buf / 4u;
    }
    fill(in, buf, 4u * nwords);
    if (split > nwords) {
        split = nwords;
    }
    want = fuzz_ref_crc(buf, nwords);
    a = j288_crc32_update_table(J288_CRC32_INIT, buf, split);
    a = j288_crc32_update_table(a, &buf[4u * split], nwords - split);
    b = j288_crc32_update_nibble(J288_CRC32_INIT, buf, split);
    b = j288_crc32_update_nibble(b, &buf[4u * split], nwords - split);
    c = j288_crc32_update_bitwise(J288_CRC32_INIT, buf, split);
    c = j288_crc32_update_bitwise(c, &buf[4u * split], nwords - split);
    FUZZ_CHECK(a == want && b == want && c == want);
    FUZZ_CHECK(j288_crc32(buf, nwords) == want);
    FUZZ_CHECK(j288_crc32_run(NULL, buf, nwords) == want);
    for (i = 0; i < 4u * nwords; i++) {
        rev[i] = buf[(i & ~(size_t)3u) + 3u - (i & 3u)];
    }
    FUZZ_CHECK(j288_crc32_mpeg2_bytes(rev, 4u * nwords) == want);

    /* Names are never NULL, whatever the number. */
    err = (int)(int32_t)fuzz_u32(in);
    FUZZ_CHECK(j288_strerror(err) != NULL && j288_strerror(err)[0] != '\0');
    bit = fuzz_u8(in);
    FUZZ_CHECK(j288_fault_name(bit) != NULL && j288_warning_name(bit) != NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_in_t in;
    uint8_t flags;
    j288_crc_t engine;
    const j288_crc_t *crc;

    if (size < 1u) {
        return 0;
    }
    flags = data[0];
    in.p = &data[1];
    in.n = size - 1u;
    crc = pick_crc(flags, &engine);
    switch (flags & 7u) {
    case 0u: case_reply_decode(&in, flags, crc); break;
    case 1u: case_cmd_decode(&in, flags, crc); break;
    case 2u: case_cmd_encode(&in, crc); break;
    case 3u: case_reply_encode(&in, crc); break;
    default: case_crc(&in); break;
    }
    return 0;
}
