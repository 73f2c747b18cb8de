/*
 * hexparse.h - hex text (as copied from a logic analyser or a terminal) to bytes.
 *
 * Accepts pairs of hex digits in either case, with or without separators: whitespace, ',',
 * ':' and a "0x" prefix before a byte are all ignored, so "fe ee 80", "FEEE80",
 * "0xfe,0xee,0x80" and "fe:ee:80" are the same three bytes.
 */
#ifndef J288_CLI_HEXPARSE_H
#define J288_CLI_HEXPARSE_H

#include <stddef.h>
#include <stdint.h>

/*
 * Parse text into out[0..cap). *len receives the number of bytes the text holds, which may
 * exceed cap (only cap are stored) so the caller can report the true length. Returns 0, or
 * -1 with a one-line reason (no trailing newline) in err: a character that is not a hex
 * digit or separator, an odd number of digits, no digits at all.
 */
int cli_hex_parse(const char *text, uint8_t *out, size_t cap, size_t *len, char *err,
                  size_t err_len);

/* Lowercase hex of data, no separators, NUL-terminated: text needs 2 * len + 1 bytes. */
void cli_hex_format(const uint8_t *data, size_t len, char *text);

#endif /* J288_CLI_HEXPARSE_H */
