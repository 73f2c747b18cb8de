/* typehash.c - see typehash.h. SHA-256 written from FIPS 180-4; the type description JSON from
 * REP-2011 (ROS 2's type_description_interfaces: FieldType ids below). */
#include "typehash.h"

#include <stdio.h>
#include <string.h>

/* ---- SHA-256 ---- */

static const uint32_t round_k[64] = {
    0x428a2f98u, 0x71374491u, 0xb5c0fbcfu, 0xe9b5dba5u, 0x3956c25bu, 0x59f111f1u, 0x923f82a4u,
    0xab1c5ed5u, 0xd807aa98u, 0x12835b01u, 0x243185beu, 0x550c7dc3u, 0x72be5d74u, 0x80deb1feu,
    0x9bdc06a7u, 0xc19bf174u, 0xe49b69c1u, 0xefbe4786u, 0x0fc19dc6u, 0x240ca1ccu, 0x2de92c6fu,
    0x4a7484aau, 0x5cb0a9dcu, 0x76f988dau, 0x983e5152u, 0xa831c66du, 0xb00327c8u, 0xbf597fc7u,
    0xc6e00bf3u, 0xd5a79147u, 0x06ca6351u, 0x14292967u, 0x27b70a85u, 0x2e1b2138u, 0x4d2c6dfcu,
    0x53380d13u, 0x650a7354u, 0x766a0abbu, 0x81c2c92eu, 0x92722c85u, 0xa2bfe8a1u, 0xa81a664bu,
    0xc24b8b70u, 0xc76c51a3u, 0xd192e819u, 0xd6990624u, 0xf40e3585u, 0x106aa070u, 0x19a4c116u,
    0x1e376c08u, 0x2748774cu, 0x34b0bcb5u, 0x391c0cb3u, 0x4ed8aa4au, 0x5b9cca4fu, 0x682e6ff3u,
    0x748f82eeu, 0x78a5636fu, 0x84c87814u, 0x8cc70208u, 0x90befffau, 0xa4506cebu, 0xbef9a3f7u,
    0xc67178f2u,
};

static uint32_t rotr(uint32_t x, unsigned n)
{
    return (x >> n) | (x << (32u - n));
}

/* One 64-byte block into the state (FIPS 180-4, 6.2.2). */
static void compress(uint32_t h[8], const uint8_t block[64])
{
    uint32_t w[64], v[8];
    unsigned t;
    for (t = 0; t < 16u; t++)
        w[t] = ((uint32_t)block[4u * t] << 24) | ((uint32_t)block[4u * t + 1u] << 16) |
               ((uint32_t)block[4u * t + 2u] << 8) | (uint32_t)block[4u * t + 3u];
    for (t = 16; t < 64u; t++) {
        uint32_t s0 = rotr(w[t - 15u], 7) ^ rotr(w[t - 15u], 18) ^ (w[t - 15u] >> 3);
        uint32_t s1 = rotr(w[t - 2u], 17) ^ rotr(w[t - 2u], 19) ^ (w[t - 2u] >> 10);
        w[t] = w[t - 16u] + s0 + w[t - 7u] + s1;
    }
    memcpy(v, h, sizeof v);
    for (t = 0; t < 64u; t++) {
        uint32_t e = v[4], a = v[0];
        uint32_t t1 = v[7] + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & v[5]) ^ (~e & v[6])) +
                      round_k[t] + w[t];
        uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & v[1]) ^ (a & v[2]) ^ (v[1] & v[2]));
        memmove(v + 1, v, 7u * sizeof v[0]);
        v[4] += t1;
        v[0] = t1 + t2;
    }
    for (t = 0; t < 8u; t++)
        h[t] += v[t];
}

void j288_sha256_init(j288_sha256_t *s)
{
    static const uint32_t h0[8] = {0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
                                   0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u};
    memcpy(s->h, h0, sizeof h0);
    s->bytes = 0;
}

void j288_sha256_update(j288_sha256_t *s, const void *data, size_t len)
{
    const uint8_t *p = data;
    while (len > 0u) {
        size_t used = (size_t)(s->bytes % 64u), take = 64u - used;
        if (take > len)
            take = len;
        memcpy(s->block + used, p, take);
        s->bytes += take;
        p += take;
        len -= take;
        if (used + take == 64u)
            compress(s->h, s->block);
    }
}

void j288_sha256_final(j288_sha256_t *s, uint8_t digest[32])
{
    uint64_t bits = s->bytes * 8u;
    uint8_t pad[72] = {0x80u};
    size_t used = (size_t)(s->bytes % 64u), n = (used < 56u ? 56u : 120u) - used;
    unsigned k;
    for (k = 0; k < 8u; k++)
        pad[n + k] = (uint8_t)(bits >> (56u - 8u * k));
    j288_sha256_update(s, pad, n + 8u);
    for (k = 0; k < 32u; k++)
        digest[k] = (uint8_t)(s->h[k / 4u] >> (24u - 8u * (k % 4u)));
}

/* ---- type descriptions ---- */

/* type_description_interfaces/msg/FieldType ids: a base type, plus 48 for a fixed array, plus
 * 144 for an unbounded sequence. */
enum {
    FT_NESTED = 1, FT_INT8 = 2, FT_UINT8 = 3, FT_INT16 = 4, FT_UINT16 = 5, FT_INT32 = 6,
    FT_UINT32 = 7, FT_FLOAT = 10, FT_DOUBLE = 11, FT_BYTE = 16, FT_STRING = 17
};
#define ARRAY(id) ((id) + 48)
#define SEQ(id) ((id) + 144)

typedef struct {
    const char *name;
    unsigned type_id;
    unsigned capacity;   /* array size (0: none) */
    const char *nested;  /* nested type name, or NULL */
} field_t;

typedef struct {
    const char *name;
    const field_t *fields;
    unsigned nfields;
} type_desc_t;

#define N(a) ((unsigned)(sizeof(a) / sizeof(a)[0]))
#define TIME "builtin_interfaces/msg/Time"
#define HEADER "std_msgs/msg/Header"

static const field_t time_f[] = {{"sec", FT_INT32, 0, NULL}, {"nanosec", FT_UINT32, 0, NULL}};
static const field_t header_f[] = {{"stamp", FT_NESTED, 0, TIME}, {"frame_id", FT_STRING, 0, NULL}};
static const field_t joint_state_f[] = {
    {"header", FT_NESTED, 0, HEADER},       {"name", SEQ(FT_STRING), 0, NULL},
    {"position", SEQ(FT_DOUBLE), 0, NULL},  {"velocity", SEQ(FT_DOUBLE), 0, NULL},
    {"effort", SEQ(FT_DOUBLE), 0, NULL},
};
static const field_t key_value_f[] = {{"key", FT_STRING, 0, NULL}, {"value", FT_STRING, 0, NULL}};
static const field_t diag_status_f[] = {
    {"level", FT_BYTE, 0, NULL},       {"name", FT_STRING, 0, NULL},
    {"message", FT_STRING, 0, NULL},   {"hardware_id", FT_STRING, 0, NULL},
    {"values", SEQ(FT_NESTED), 0, "diagnostic_msgs/msg/KeyValue"},
};
static const field_t diag_array_f[] = {
    {"header", FT_NESTED, 0, HEADER},
    {"status", SEQ(FT_NESTED), 0, "diagnostic_msgs/msg/DiagnosticStatus"},
};

/* unitree_go (tools/j288-dds/idl/unitree_go.idl) */
static const field_t go_motor_cmd_f[] = {
    {"mode", FT_UINT8, 0, NULL}, {"q", FT_FLOAT, 0, NULL},  {"dq", FT_FLOAT, 0, NULL},
    {"tau", FT_FLOAT, 0, NULL},  {"kp", FT_FLOAT, 0, NULL}, {"kd", FT_FLOAT, 0, NULL},
    {"reserve", ARRAY(FT_UINT32), 3, NULL},
};
static const field_t go_motor_state_f[] = {
    {"mode", FT_UINT8, 0, NULL},       {"q", FT_FLOAT, 0, NULL},       {"dq", FT_FLOAT, 0, NULL},
    {"ddq", FT_FLOAT, 0, NULL},        {"tau_est", FT_FLOAT, 0, NULL}, {"q_raw", FT_FLOAT, 0, NULL},
    {"dq_raw", FT_FLOAT, 0, NULL},     {"ddq_raw", FT_FLOAT, 0, NULL},
    {"temperature", FT_UINT8, 0, NULL}, {"lost", FT_UINT32, 0, NULL},
    {"reserve", ARRAY(FT_UINT32), 2, NULL},
};
static const field_t go_bms_cmd_f[] = {{"off", FT_UINT8, 0, NULL}, {"reserve", ARRAY(FT_UINT8), 3, NULL}};
static const field_t go_bms_state_f[] = {
    {"version_high", FT_UINT8, 0, NULL}, {"version_low", FT_UINT8, 0, NULL},
    {"status", FT_UINT8, 0, NULL},       {"soc", FT_UINT8, 0, NULL},
    {"current", FT_INT32, 0, NULL},      {"cycle", FT_UINT16, 0, NULL},
    {"bq_ntc", ARRAY(FT_UINT8), 2, NULL}, {"mcu_ntc", ARRAY(FT_UINT8), 2, NULL},
    {"cell_vol", ARRAY(FT_UINT16), 15, NULL},
};
static const field_t go_imu_f[] = {
    {"quaternion", ARRAY(FT_FLOAT), 4, NULL},    {"gyroscope", ARRAY(FT_FLOAT), 3, NULL},
    {"accelerometer", ARRAY(FT_FLOAT), 3, NULL}, {"rpy", ARRAY(FT_FLOAT), 3, NULL},
    {"temperature", FT_UINT8, 0, NULL},
};
#define GO_HEAD                                                                                  \
    {"head", ARRAY(FT_UINT8), 2, NULL}, {"level_flag", FT_UINT8, 0, NULL},                       \
        {"frame_reserve", FT_UINT8, 0, NULL}, {"sn", ARRAY(FT_UINT32), 2, NULL},                 \
        {"version", ARRAY(FT_UINT32), 2, NULL}, {"bandwidth", FT_UINT16, 0, NULL}
static const field_t go_lowcmd_f[] = {
    GO_HEAD,
    {"motor_cmd", ARRAY(FT_NESTED), 20, "unitree_go/msg/MotorCmd"},
    {"bms_cmd", FT_NESTED, 0, "unitree_go/msg/BmsCmd"},
    {"wireless_remote", ARRAY(FT_UINT8), 40, NULL},
    {"led", ARRAY(FT_UINT8), 12, NULL},
    {"fan", ARRAY(FT_UINT8), 2, NULL},
    {"gpio", FT_UINT8, 0, NULL},
    {"reserve", FT_UINT32, 0, NULL},
    {"crc", FT_UINT32, 0, NULL},
};
static const field_t go_lowstate_f[] = {
    GO_HEAD,
    {"imu_state", FT_NESTED, 0, "unitree_go/msg/IMUState"},
    {"motor_state", ARRAY(FT_NESTED), 20, "unitree_go/msg/MotorState"},
    {"bms_state", FT_NESTED, 0, "unitree_go/msg/BmsState"},
    {"foot_force", ARRAY(FT_INT16), 4, NULL},
    {"foot_force_est", ARRAY(FT_INT16), 4, NULL},
    {"tick", FT_UINT32, 0, NULL},
    {"wireless_remote", ARRAY(FT_UINT8), 40, NULL},
    {"bit_flag", FT_UINT8, 0, NULL},
    {"adc_reel", FT_FLOAT, 0, NULL},
    {"temperature_ntc1", FT_UINT8, 0, NULL},
    {"temperature_ntc2", FT_UINT8, 0, NULL},
    {"power_v", FT_FLOAT, 0, NULL},
    {"power_a", FT_FLOAT, 0, NULL},
    {"fan_frequency", ARRAY(FT_UINT16), 4, NULL},
    {"reserve", FT_UINT32, 0, NULL},
    {"crc", FT_UINT32, 0, NULL},
};

/* unitree_hg (tools/j288-dds/idl/unitree_hg.idl) */
static const field_t hg_motor_cmd_f[] = {
    {"mode", FT_UINT8, 0, NULL}, {"q", FT_FLOAT, 0, NULL},  {"dq", FT_FLOAT, 0, NULL},
    {"tau", FT_FLOAT, 0, NULL},  {"kp", FT_FLOAT, 0, NULL}, {"kd", FT_FLOAT, 0, NULL},
    {"reserve", FT_UINT32, 0, NULL},
};
static const field_t hg_motor_state_f[] = {
    {"mode", FT_UINT8, 0, NULL},    {"q", FT_FLOAT, 0, NULL},   {"dq", FT_FLOAT, 0, NULL},
    {"ddq", FT_FLOAT, 0, NULL},     {"tau_est", FT_FLOAT, 0, NULL},
    {"temperature", ARRAY(FT_INT16), 2, NULL}, {"vol", FT_FLOAT, 0, NULL},
    {"sensor", ARRAY(FT_UINT32), 2, NULL},     {"motorstate", FT_UINT32, 0, NULL},
    {"reserve", ARRAY(FT_UINT32), 4, NULL},
};
static const field_t hg_imu_f[] = {
    {"quaternion", ARRAY(FT_FLOAT), 4, NULL},    {"gyroscope", ARRAY(FT_FLOAT), 3, NULL},
    {"accelerometer", ARRAY(FT_FLOAT), 3, NULL}, {"rpy", ARRAY(FT_FLOAT), 3, NULL},
    {"temperature", FT_INT16, 0, NULL},
};
static const field_t hg_lowcmd_f[] = {
    {"mode_pr", FT_UINT8, 0, NULL},
    {"mode_machine", FT_UINT8, 0, NULL},
    {"motor_cmd", ARRAY(FT_NESTED), 35, "unitree_hg/msg/MotorCmd"},
    {"reserve", ARRAY(FT_UINT32), 4, NULL},
    {"crc", FT_UINT32, 0, NULL},
};
static const field_t hg_lowstate_f[] = {
    {"version", ARRAY(FT_UINT32), 2, NULL},
    {"mode_pr", FT_UINT8, 0, NULL},
    {"mode_machine", FT_UINT8, 0, NULL},
    {"tick", FT_UINT32, 0, NULL},
    {"imu_state", FT_NESTED, 0, "unitree_hg/msg/IMUState"},
    {"motor_state", ARRAY(FT_NESTED), 35, "unitree_hg/msg/MotorState"},
    {"wireless_remote", ARRAY(FT_UINT8), 40, NULL},
    {"reserve", ARRAY(FT_UINT32), 4, NULL},
    {"crc", FT_UINT32, 0, NULL},
};

/* Every type, sorted by name (the order of referenced_type_descriptions). */
static const type_desc_t types[] = {
    {TIME, time_f, N(time_f)},
    {"diagnostic_msgs/msg/DiagnosticArray", diag_array_f, N(diag_array_f)},
    {"diagnostic_msgs/msg/DiagnosticStatus", diag_status_f, N(diag_status_f)},
    {"diagnostic_msgs/msg/KeyValue", key_value_f, N(key_value_f)},
    {"sensor_msgs/msg/JointState", joint_state_f, N(joint_state_f)},
    {HEADER, header_f, N(header_f)},
    {"unitree_go/msg/BmsCmd", go_bms_cmd_f, N(go_bms_cmd_f)},
    {"unitree_go/msg/BmsState", go_bms_state_f, N(go_bms_state_f)},
    {"unitree_go/msg/IMUState", go_imu_f, N(go_imu_f)},
    {"unitree_go/msg/LowCmd", go_lowcmd_f, N(go_lowcmd_f)},
    {"unitree_go/msg/LowState", go_lowstate_f, N(go_lowstate_f)},
    {"unitree_go/msg/MotorCmd", go_motor_cmd_f, N(go_motor_cmd_f)},
    {"unitree_go/msg/MotorState", go_motor_state_f, N(go_motor_state_f)},
    {"unitree_hg/msg/IMUState", hg_imu_f, N(hg_imu_f)},
    {"unitree_hg/msg/LowCmd", hg_lowcmd_f, N(hg_lowcmd_f)},
    {"unitree_hg/msg/LowState", hg_lowstate_f, N(hg_lowstate_f)},
    {"unitree_hg/msg/MotorCmd", hg_motor_cmd_f, N(hg_motor_cmd_f)},
    {"unitree_hg/msg/MotorState", hg_motor_state_f, N(hg_motor_state_f)},
};
#define NTYPES N(types)

static const char *const top_names[J288_DDS_NTYPES] = {
    "sensor_msgs/msg/JointState", "diagnostic_msgs/msg/DiagnosticArray",
    "unitree_go/msg/LowCmd",      "unitree_go/msg/LowState",
    "unitree_hg/msg/LowCmd",      "unitree_hg/msg/LowState",
};

const char *j288_dds_type_name(j288_dds_type_t t)
{
    return (unsigned)t < J288_DDS_NTYPES ? top_names[t] : "?";
}

static int find_type(const char *name)
{
    unsigned i;
    for (i = 0; i < NTYPES; i++)
        if (strcmp(types[i].name, name) == 0)
            return (int)i;
    return -1;
}

/* Mark every type t refers to, directly or not. */
static void mark_references(unsigned t, unsigned char used[NTYPES])
{
    unsigned f;
    for (f = 0; f < types[t].nfields; f++) {
        int k = types[t].fields[f].nested != NULL ? find_type(types[t].fields[f].nested) : -1;
        if (k >= 0 && !used[k]) {
            used[k] = 1;
            mark_references((unsigned)k, used);
        }
    }
}

static void put(j288_sha256_t *s, const char *text)
{
    j288_sha256_update(s, text, strlen(text));
}

/* {"type_name": ..., "fields": [...]}: names are plain identifiers, nothing to escape. */
static void put_type(j288_sha256_t *s, const type_desc_t *t)
{
    char buf[256];
    unsigned f;
    put(s, "{\"type_name\": \"");
    put(s, t->name);
    put(s, "\", \"fields\": [");
    for (f = 0; f < t->nfields; f++) {
        const field_t *fd = &t->fields[f];
        snprintf(buf, sizeof buf,
                 "%s{\"name\": \"%s\", \"type\": {\"type_id\": %u, \"capacity\": %u, "
                 "\"string_capacity\": 0, \"nested_type_name\": \"%s\"}}",
                 f == 0u ? "" : ", ", fd->name, fd->type_id, fd->capacity,
                 fd->nested != NULL ? fd->nested : "");
        put(s, buf);
    }
    put(s, "]}");
}

void j288_dds_typehash(j288_dds_type_t t, char out[J288_DDS_TYPEHASH_LEN])
{
    unsigned char used[NTYPES];
    j288_sha256_t s;
    uint8_t d[32];
    unsigned i, first = 1;
    int top = (unsigned)t < J288_DDS_NTYPES ? find_type(top_names[t]) : -1;
    out[0] = '\0';
    if (top < 0)
        return;
    memset(used, 0, sizeof used);
    mark_references((unsigned)top, used);
    j288_sha256_init(&s);
    put(&s, "{\"type_description\": ");
    put_type(&s, &types[top]);
    put(&s, ", \"referenced_type_descriptions\": [");
    for (i = 0; i < NTYPES; i++) {
        if (!used[i])
            continue;
        if (!first)
            put(&s, ", ");
        first = 0;
        put_type(&s, &types[i]);
    }
    put(&s, "]}");
    j288_sha256_final(&s, d);
    memcpy(out, "RIHS01_", 7u);
    for (i = 0; i < 32u; i++)
        snprintf(out + 7u + 2u * i, 3u, "%02x", d[i]);
}
