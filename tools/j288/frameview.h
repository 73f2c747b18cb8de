/*
 * frameview.h - how the j288 tool shows a command or a reply: a human table (raw values and
 * SI units on both sides of the gear) and JSON objects. Shared by `decode`, `status`, `scan`.
 */
#ifndef J288_CLI_FRAMEVIEW_H
#define J288_CLI_FRAMEVIEW_H

#include <stdio.h>

#include "j288/j288.h"
#include "json.h"

/* "lock", "foc", or "status N" for the other values a reply can carry. */
const char *cli_mode_name(unsigned status);

/* Fault names joined with ", " into buf ("none" when 0); unknown bits as "unknown fault
 * (bit N)". Returns buf. */
const char *cli_fault_list(uint32_t faults, char *buf, size_t len);
const char *cli_warning_list(unsigned warnings, char *buf, size_t len);

/* Human tables under a title line (e.g. "reply frame: 26 bytes, CRC 0x... ok"). */
void cli_show_cmd(FILE *f, const j288_cmd_raw_t *cmd, const char *title);
void cli_show_reply(FILE *f, const j288_reply_raw_t *r, const char *title);

/* JSON members for an object the caller has opened: every raw field under the keys the
 * issue fixes (frame, id, mode, watchdog, ...), plus names and SI values under "rotor" and
 * "output". */
void cli_json_cmd_members(cli_json_t *j, const j288_cmd_raw_t *cmd);
void cli_json_reply_members(cli_json_t *j, const j288_reply_raw_t *r);

#endif /* J288_CLI_FRAMEVIEW_H */
