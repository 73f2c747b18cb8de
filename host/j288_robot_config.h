/*
 * j288_robot_config.h - the robot config file: buses and joints in YAML, read into a plain struct
 * and written back in place (host side; needs libyaml, Debian's libyaml-dev).
 *
 * The file: examples/robot.yaml is the reference, every key there with its meaning, unit,
 * default and range (a test loads it, so it stays a file this reader takes). In short:
 * 'buses:' (each a name, a port, and optionally baud, margin_us, echo) and 'joints:' (each a
 * name and an id, and optionally bus, direction, zero, limits, max_speed, max_torque, kp, kd,
 * phase, clamp, continuous). A relative port (sim/bus0) is taken from the config file's
 * folder, not from where the program runs (j288_robot_config_load();
 * j288_robot_config_parse() has no folder and keeps it as written).
 *
 * Reading is strict, so that a typo never silently becomes a default: unknown or repeated
 * keys, values of the wrong type (numbers must be plain, e.g. 1.5, not "1.5", in the syntax the
 * j288 tool's options take too: host/j288_number.h, decimal reals, decimal or 0x whole
 * numbers; booleans are true or false), names that repeat, an id used twice on one bus, and
 * values out of range (each key's range is the library's: the message names the key, the
 * value as written and the range) are errors. Every error is one line "FILE:LINE: what is
 * wrong" (LINE counts from 1; syntax errors name the column too). Refused as well: aliases
 * (*name; a value written back must belong to one joint only), YAML tags (!!str 1: a key's
 * type is its own, a tag would contradict or repeat it), more than one document, and lists
 * and mappings nested deeper than J288_ROBOT_CONFIG_MAX_DEPTH (refused as soon as the reader
 * gets there: libyaml's time grows with the square of the depth).
 *
 * Writing back (j288_robot_config_write_joint) changes one joint's zero and/or phase in the file's
 * own text: an existing value is replaced where it stands; a missing key is added as a line
 * "key: value" at the end of the joint's block mapping, with its indentation and line ending.
 * Comments, order, formatting and every other byte are kept. The result is read back and
 * compared with the original before anything is written (only the changed values may
 * differ), then replaces the file atomically (a temporary file in the same folder, renamed
 * over it; the file's permission bits are kept; a symlink is followed, not replaced). A
 * joint written as a flow mapping ({name: hip, ...}) can have values replaced, not added.
 * A file the user may not write, or without any write permission bit (root too: renaming
 * over it would not ask), is refused (j288_robot_config_check_writable() tells beforehand,
 * before a tool moves anything). The temporary file is ".NAME.j288-PID.XXXXXX" beside the
 * file: removed on every error; one left by a write-back that was killed (SIGKILL, power
 * loss) is removed by the next write-back of the same file once process PID is gone.
 *
 * No allocation by callers: structures are caller-allocated with fixed capacities (the
 * functions allocate internally for the file's text and libyaml's document, and free it
 * before they return). Not thread-safe per object; functions are reentrant. When the build
 * found no libyaml, every function that reads or writes a file fails with a message saying so
 * (j288_robot_config_available() tells beforehand).
 */
#ifndef J288_ROBOT_CONFIG_H
#define J288_ROBOT_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/joint.h"

#ifdef __cplusplus
extern "C" {
#endif

#define J288_ROBOT_CONFIG_MAX_BUSES  16u
#define J288_ROBOT_CONFIG_MAX_JOINTS 64u
#define J288_ROBOT_CONFIG_NAME_MAX   32u             /* bytes with the terminating NUL */
#define J288_ROBOT_CONFIG_PORT_MAX   256u            /* bytes with the terminating NUL */
#define J288_ROBOT_CONFIG_FILE_MAX   (1024u * 1024u) /* largest file read */
#define J288_ROBOT_CONFIG_ERROR_MAX  512u            /* holds any message for a name below 200 bytes */
#define J288_ROBOT_CONFIG_MAX_DEPTH  8u              /* lists and mappings inside each other (a
                                                        valid file needs 4) */
#define J288_ROBOT_CONFIG_NO_BUS     (-1)            /* joint.bus when the file has no buses */

typedef struct {
    char name[J288_ROBOT_CONFIG_NAME_MAX];
    char port[J288_ROBOT_CONFIG_PORT_MAX];
    bool has_baud;
    uint32_t baud; /* bit/s, above 0 */
    bool has_margin_us;
    uint32_t margin_us;
    bool has_echo;
    bool echo;
    unsigned line; /* where the entry starts in the file */
} j288_robot_config_bus_t;

/* One joint, defaults filled in (the has_ flags say what the file gave). */
typedef struct {
    char name[J288_ROBOT_CONFIG_NAME_MAX];
    int bus;       /* index into j288_robot_config_t.bus[], or J288_ROBOT_CONFIG_NO_BUS */
    uint8_t id;    /* 0-14 */
    int direction; /* +1 or -1 */
    double zero;   /* rad, output-encoder frame */
    bool has_limits;
    double pos_min, pos_max; /* rad, joint frame; default -pi, pi */
    bool has_max_speed;
    double max_speed; /* rad/s, joint frame */
    bool has_max_torque;
    double max_torque; /* N*m, joint frame */
    bool has_kp;
    double kp; /* N*m/rad, joint frame */
    bool has_kd;
    double kd; /* N*m*s/rad, joint frame */
    bool has_phase;
    double phase; /* rotor rad */
    bool clamp;
    bool continuous; /* a wheel: no limits (pos_min / pos_max unused), the angle unbounded */
    unsigned line;   /* where the entry starts in the file */
} j288_robot_config_joint_t;

typedef struct {
    size_t nbuses;
    j288_robot_config_bus_t bus[J288_ROBOT_CONFIG_MAX_BUSES];
    size_t njoints;
    j288_robot_config_joint_t joint[J288_ROBOT_CONFIG_MAX_JOINTS];
} j288_robot_config_t;

/* What j288_robot_config_write_joint() changes: the values whose set_ flag is true. */
typedef struct {
    bool set_zero;
    double zero;
    bool set_phase;
    double phase;
} j288_robot_config_update_t;

/* True when the build has libyaml (robot config support). */
bool j288_robot_config_available(void);

/* Read and check the file at path into *cfg. 0 on success; -1 with a one-line message in err
 * (errlen bytes, J288_ROBOT_CONFIG_ERROR_MAX is always enough) and *cfg unspecified. */
int j288_robot_config_load(const char *path, j288_robot_config_t *cfg, char *err, size_t errlen);

/* The same from len bytes of text in memory; name stands for the file in messages. */
int j288_robot_config_parse(const char *text, size_t len, const char *name, j288_robot_config_t *cfg, char *err,
                      size_t errlen);

/* The joint called name, or NULL. */
const j288_robot_config_joint_t *j288_robot_config_find_joint(const j288_robot_config_t *cfg, const char *name);

/* The index of the bus called name, or -1. */
int j288_robot_config_find_bus(const j288_robot_config_t *cfg, const char *name);

/* Change joint's zero and/or phase in the file at path (see the top of this header). The
 * values must be finite and within the ranges the file is read with (zero +-64 rad,
 * J288_JOINT_MAX_ANGLE; phase +-2 pi). 0 on success; -1 with a message in err, the file
 * then untouched (an error while replacing it leaves the old file in place). */
int j288_robot_config_write_joint(const char *path, const char *joint, const j288_robot_config_update_t *upd,
                            char *err, size_t errlen);

/* 0 when j288_robot_config_write_joint() could replace the file at path (a regular file the
 * user may write, with a write permission bit, in a folder the user may write); -1 with a
 * message in err saying what stands in the way. Reads nothing but the file's metadata. */
int j288_robot_config_check_writable(const char *path, char *err, size_t errlen);

/* The library's configuration of a joint read from the file (j288/joint.h): id, direction,
 * zero, clamp, continuous and phase as given; limits, max_speed, max_torque, kp and kd as
 * given, else 0 (the library's defaults: [-pi, pi], no speed or torque limit beyond the
 * wire's, no default gains); the start's sample count and tolerances at the library's
 * defaults (0). Checks nothing: j288_joint_init() does, and the file's own checks keep its
 * values in the ranges the library takes. Works without libyaml. NULL arguments are ignored. */
void j288_robot_config_joint_config(const j288_robot_config_joint_t *rj, j288_joint_config_t *jc);

/* The text-level edit behind j288_robot_config_write_joint(): the len bytes of text in, the edited
 * text in out (outcap bytes: len plus, per key added, the joint's indentation plus 100), its
 * length in *outlen (out is not NUL-terminated). name stands for the file in messages. Same
 * checks and results; writes no file. */
int j288_robot_config_edit(const char *text, size_t len, const char *name, const char *joint,
                     const j288_robot_config_update_t *upd, char *out, size_t outcap, size_t *outlen,
                     char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* J288_ROBOT_CONFIG_H */
