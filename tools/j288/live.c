/* The live screens' terminal and frames; see live.h. */
#include "live.h"

#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include "j288/j288.h"

static struct termios g_saved_tty;
static bool g_tty_raw;

bool cli_live_raw(void)
{
    struct termios t;
    if (g_tty_raw)
        return true;
    if (!isatty(STDIN_FILENO) || tcgetattr(STDIN_FILENO, &g_saved_tty) != 0)
        return false;
    t = g_saved_tty;
    t.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    g_tty_raw = tcsetattr(STDIN_FILENO, TCSANOW, &t) == 0;
    return g_tty_raw;
}

void cli_live_restore(void)
{
    if (g_tty_raw)
        (void)tcsetattr(STDIN_FILENO, TCSANOW, &g_saved_tty);
    g_tty_raw = false;
}

/* Bytes read but not yet handed out as keys. */
static unsigned char g_pending[32];
static size_t g_npending;

static void fill_pending(void)
{
    struct pollfd p;
    ssize_t n;
    p.fd = STDIN_FILENO;
    p.events = POLLIN;
    p.revents = 0;
    if (!g_tty_raw || g_npending == sizeof g_pending || poll(&p, 1, 0) != 1)
        return;
    n = read(STDIN_FILENO, g_pending + g_npending, sizeof g_pending - g_npending);
    if (n > 0)
        g_npending += (size_t)n;
}

static void drop_pending(size_t n)
{
    memmove(g_pending, g_pending + n, g_npending - n);
    g_npending -= n;
}

int cli_live_key(void)
{
    static const char arrows[] = "ABCD";
    static const int keys[] = {CLI_KEY_UP, CLI_KEY_DOWN, CLI_KEY_RIGHT, CLI_KEY_LEFT};
    int c;
    size_t i;
    if (g_npending < 3u)
        fill_pending();
    if (g_npending == 0u)
        return CLI_KEY_NONE;
    c = g_pending[0];
    if (c != 0x1b || g_npending == 1u) { /* a plain byte, or ESC alone */
        drop_pending(1);
        return c;
    }
    if (g_pending[1] != '[' && g_pending[1] != 'O') {
        drop_pending(1);
        return c;
    }
    /* ESC [ or ESC O: the final byte of the sequence (0x40-0x7e) ends it */
    for (i = 2; i < g_npending && (g_pending[i] < 0x40u || g_pending[i] > 0x7eu); i++) {
    }
    if (i == g_npending) { /* incomplete: drop what there is */
        g_npending = 0;
        return CLI_KEY_NONE;
    }
    c = CLI_KEY_NONE;
    if (i == 2u && strchr(arrows, g_pending[2]) != NULL)
        c = keys[strchr(arrows, g_pending[2]) - arrows];
    drop_pending(i + 1u);
    return c == CLI_KEY_NONE ? cli_live_key() : c;
}

void cli_live_size(unsigned *cols, unsigned *rows)
{
    struct winsize ws;
    *cols = 80;
    *rows = 24;
    if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
        *cols = ws.ws_col;
        *rows = ws.ws_row;
    }
}

bool cli_live_frame_begin(cli_live_frame_t *fr)
{
    fr->text = NULL;
    fr->len = 0;
    fr->f = open_memstream(&fr->text, &fr->len);
    return fr->f != NULL;
}

size_t cli_live_cut(const char *line, size_t len, unsigned cols, char *out, size_t cap)
{
    size_t i = 0, n = 0;
    unsigned cells = 0;
    if (cap == 0u)
        return 0;
    while (i < len) {
        size_t k = 1;
        bool visible = true;
        unsigned char c = (unsigned char)line[i];
        if (c == 0x1bu && i + 1u < len && line[i + 1] == '[') {
            /* CSI: parameters up to a final byte 0x40-0x7e */
            for (k = 2; i + k < len && ((unsigned char)line[i + k] < 0x40u ||
                                        (unsigned char)line[i + k] > 0x7eu);
                 k++) {
            }
            k = i + k < len ? k + 1u : len - i;
            visible = false;
        } else if (c >= 0xC0u) {
            while (i + k < len && ((unsigned char)line[i + k] & 0xC0u) == 0x80u)
                k++;
        }
        if (visible && cells >= cols) {
            i += k;
            continue;
        }
        if (n + k >= cap)
            break;
        memcpy(out + n, line + i, k);
        n += k;
        i += k;
        cells += visible ? 1u : 0u;
    }
    out[n] = '\0';
    return n;
}

/* The whole of text to stdout in as few writes as the terminal takes (one, normally): a
 * frame drawn in pieces could be seen half old, half new. */
static void write_all(const char *text, size_t len)
{
    (void)fflush(stdout);
    while (len > 0u) {
        ssize_t n = write(STDOUT_FILENO, text, len);
        if (n <= 0)
            return; /* the terminal is gone: nothing to show it on */
        text += n;
        len -= (size_t)n;
    }
}

void cli_live_frame_show(cli_live_frame_t *fr, unsigned cols, unsigned rows)
{
    const char *p, *end;
    unsigned shown = 0;
    cli_live_frame_t out;
    if (fclose(fr->f) != 0 || fr->text == NULL || !cli_live_frame_begin(&out)) {
        free(fr->text);
        fr->text = NULL;
        return;
    }
    fputs("\033[H", out.f);
    p = fr->text;
    end = fr->text + fr->len;
    while (p < end && shown + 1u < rows) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = nl != NULL ? (size_t)(nl - p) : (size_t)(end - p);
        char cut[4096];
        (void)cli_live_cut(p, len, cols, cut, sizeof cut);
        fputs(cut, out.f);
        fputs("\033[K\n", out.f);
        shown++;
        p += len + (nl != NULL ? 1u : 0u);
    }
    fputs("\033[J", out.f);
    free(fr->text);
    fr->text = NULL;
    if (fclose(out.f) == 0 && out.text != NULL)
        write_all(out.text, out.len);
    free(out.text);
}

void cli_live_bus_config(const char *port, uint32_t ids, j288_robot_config_t *cfg)
{
    j288_robot_config_bus_t *b = &cfg->bus[0];
    unsigned id;
    memset(cfg, 0, sizeof *cfg);
    cfg->nbuses = 1;
    (void)snprintf(b->name, sizeof b->name, "bus");
    (void)snprintf(b->port, sizeof b->port, "%s", port);
    for (id = 0; id <= J288_MAX_ID; id++) {
        j288_robot_config_joint_t *jt = &cfg->joint[cfg->njoints];
        if ((ids & (1ul << id)) == 0u)
            continue;
        (void)snprintf(jt->name, sizeof jt->name, "id%u", id);
        jt->bus = 0;
        jt->id = (uint8_t)id;
        jt->direction = 1;
        cfg->njoints++;
    }
}

void cli_live_plot(FILE *f, const cli_tplot_t *p, uint32_t mask, unsigned cols, unsigned rows,
                   double min_span, double span_s, bool color)
{
    static const char *const palette[] = {"32", "33", "36", "35"};
    static cli_tplot_canvas_t c; /* large: not on the stack */
    const char *colors[CLI_TPLOT_MAX_SERIES];
    char line[CLI_TPLOT_MAX_WIDTH * 16u];
    unsigned r, s, k = 0, width;
    if (cols < 20u || rows < 2u)
        return;
    width = cols - 11u;
    memset(colors, 0, sizeof colors);
    for (s = 0; s < CLI_TPLOT_MAX_SERIES; s++)
        if ((mask & (1ul << s)) != 0u)
            colors[s] = palette[k++ % 4u];
    cli_tplot_render(p, mask, width, rows, min_span, &c);
    for (r = 0; r < c.rows; r++) {
        char label[16] = "";
        if (!c.empty && (r == 0u || r + 1u == c.rows))
            (void)snprintf(label, sizeof label, "%9.4f", r == 0u ? c.top : c.bottom);
        (void)cli_tplot_line(&c, r, color ? colors : NULL, line, sizeof line);
        fprintf(f, "%9s |%s\n", label, line);
    }
    {
        char past[32];
        (void)snprintf(past, sizeof past, "<- %.1f s", span_s);
        fprintf(f, "%9s  %-*s now\n", "", (int)(width > 4u ? width - 4u : 0u), past);
    }
}
