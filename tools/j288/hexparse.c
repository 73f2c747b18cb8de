/* Hex text to bytes; see hexparse.h. */
#include "hexparse.h"

#include <stdio.h>

static int hex_value(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

static int is_separator(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',' || c == ':';
}

int cli_hex_parse(const char *text, uint8_t *out, size_t cap, size_t *len, char *err,
                  size_t err_len)
{
    size_t digits = 0;
    size_t i;
    unsigned hi = 0;

    for (i = 0; text[i] != '\0'; i++) {
        char c = text[i];
        int v;
        if (is_separator(c)) {
            continue;
        }
        /* "0x" only at the start of a byte, so "0x" never eats a real '0' digit pair; "0x5"
         * followed by a separator is the byte 05. */
        if (c == '0' && (text[i + 1] == 'x' || text[i + 1] == 'X') && digits % 2u == 0u) {
            i++;
            if (hex_value(text[i + 1]) >= 0 && (text[i + 2] == '\0' || is_separator(text[i + 2]))) {
                if (digits / 2u < cap) {
                    out[digits / 2u] = (uint8_t)hex_value(text[i + 1]);
                }
                digits += 2u;
                i++;
            }
            continue;
        }
        v = hex_value(c);
        if (v < 0) {
            if ((unsigned char)c >= 0x20u && (unsigned char)c < 0x7fu) {
                snprintf(err, err_len, "not hex: '%c' at character %zu", c, i + 1u);
            } else {
                snprintf(err, err_len, "not hex: byte 0x%02x at character %zu",
                         (unsigned)(unsigned char)c, i + 1u);
            }
            return -1;
        }
        if (digits % 2u == 0u) {
            hi = (unsigned)v;
        } else if (digits / 2u < cap) {
            out[digits / 2u] = (uint8_t)((hi << 4) | (unsigned)v);
        }
        digits++;
    }
    if (digits == 0u) {
        snprintf(err, err_len, "no hex digits given");
        return -1;
    }
    if (digits % 2u != 0u) {
        snprintf(err, err_len, "odd number of hex digits (%zu): every byte needs two", digits);
        return -1;
    }
    *len = digits / 2u;
    return 0;
}

void cli_hex_format(const uint8_t *data, size_t len, char *text)
{
    static const char digit[] = "0123456789abcdef";
    size_t i;
    for (i = 0; i < len; i++) {
        text[2u * i] = digit[data[i] >> 4];
        text[2u * i + 1u] = digit[data[i] & 0x0Fu];
    }
    text[2u * len] = '\0';
}
