/*
 * typehash.h - ROS 2's type hash of the bridge's message types (REP-2011, "RIHS01"), for the
 * USER_DATA `typehash=RIHS01_<hex>;` that ROS 2's rmw puts on every reader and writer (ROS 2
 * Iron and later read it from each endpoint they discover; Jazzy's rmw_cyclonedds logs
 * "Failed to parse type hash" for every endpoint without one).
 *
 * The hash of a type is SHA-256 over its type description as JSON: the type's name and fields
 * (each with its name, type id, capacity, string capacity and nested type name; no default
 * values), then every type it refers to, directly or not, sorted by name, written with ", "
 * and ": " as separators. The descriptions here are ROS 2's messages (sensor_msgs/JointState,
 * diagnostic_msgs/DiagnosticArray) as ROS 2 declares them, whatever bounds the bridge's own IDL
 * adds, and unitree_go's and unitree_hg's messages as tools/j288-dds/idl declares them.
 * test/dds checks them against the hashes ROS 2 publishes and against an independent
 * computation from the IDL (test/dds/typehash.py).
 *
 * Pure functions over constant tables: reentrant.
 */
#ifndef J288_DDS_TYPEHASH_H
#define J288_DDS_TYPEHASH_H

#include <stddef.h>
#include <stdint.h>

/* "RIHS01_" and 64 lowercase hex digits, and the NUL. */
#define J288_DDS_TYPEHASH_LEN 72u

typedef enum {
    J288_DDS_TYPE_JOINT_STATE = 0,    /* sensor_msgs/msg/JointState */
    J288_DDS_TYPE_DIAGNOSTIC_ARRAY,   /* diagnostic_msgs/msg/DiagnosticArray */
    J288_DDS_TYPE_GO_LOWCMD,          /* unitree_go/msg/LowCmd */
    J288_DDS_TYPE_GO_LOWSTATE,        /* unitree_go/msg/LowState */
    J288_DDS_TYPE_HG_LOWCMD,          /* unitree_hg/msg/LowCmd */
    J288_DDS_TYPE_HG_LOWSTATE,        /* unitree_hg/msg/LowState */
    J288_DDS_NTYPES
} j288_dds_type_t;

/* The type's ROS 2 name ("pkg/msg/Name"), or "?" for a bad value. */
const char *j288_dds_type_name(j288_dds_type_t t);

/* The type's hash, "RIHS01_..." into out (J288_DDS_TYPEHASH_LEN bytes); "" for a bad value. */
void j288_dds_typehash(j288_dds_type_t t, char out[J288_DDS_TYPEHASH_LEN]);

/* SHA-256 (FIPS 180-4), streaming, for the hash above. */
typedef struct {
    uint32_t h[8];
    uint64_t bytes;     /* taken so far */
    uint8_t block[64];  /* the block being filled */
} j288_sha256_t;

void j288_sha256_init(j288_sha256_t *s);
void j288_sha256_update(j288_sha256_t *s, const void *data, size_t len);
void j288_sha256_final(j288_sha256_t *s, uint8_t digest[32]);

#endif
