/* `j288 plot`: position, speed and torque against time from a `j288 log` CSV, drawn by
 * gnuplot into a PNG. Without gnuplot: a one-line notice and exit 3 (CLI_EXIT_NO_TOOL). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "args.h"
#include "cli.h"

static const char plot_help[] =
    "usage: j288 plot FILE.csv --png OUT.png\n"
    "\n"
    "Draw position (with the commanded position dashed), speed and torque against time,\n"
    "one line per servo, from a CSV written by `j288 log`, using gnuplot, in the frame the\n"
    "log was written in (the joint frame unless log was given --side rotor or output).\n"
    "Exit status: 0 PNG written; 1 unreadable CSV or gnuplot failed; 2 bad arguments;\n"
    "3 gnuplot is not installed (install the Debian package gnuplot-nox).\n";

enum { OPT_PNG };

/* gnuplot on PATH? */
static bool have_program(const char *name)
{
    const char *path = getenv("PATH");
    char candidate[4096];
    while (path != NULL && *path != '\0') {
        const char *colon = strchr(path, ':');
        size_t n = colon != NULL ? (size_t)(colon - path) : strlen(path);
        if (n > 0u && n + strlen(name) + 2u < sizeof candidate) {
            memcpy(candidate, path, n);
            candidate[n] = '/';
            strcpy(candidate + n + 1u, name);
            if (access(candidate, X_OK) == 0) {
                return true;
            }
        }
        path = colon != NULL ? colon + 1 : NULL;
    }
    return false;
}

/* One CSV line of `j288 log` split at commas (the fields hold no commas). */
/* Whether the PNG can be written (checked before gnuplot, which, refused, would write it to
 * the terminal); one error line if not. A file that did not exist is not left behind. */
static bool png_writable(const char *png)
{
    struct stat st;
    bool existed = stat(png, &st) == 0;
    FILE *f = fopen(png, "a");
    if (f == NULL) {
        cli_error("cannot write %s: %s", png, strerror(errno));
        return false;
    }
    (void)fclose(f);
    if (!existed) {
        (void)remove(png);
    }
    return true;
}

#define CSV_FIELDS 12
static int split_csv(char *line, char *field[CSV_FIELDS])
{
    int n = 0;
    char *p = line;
    line[strcspn(line, "\r\n")] = '\0';
    while (n < CSV_FIELDS) {
        field[n++] = p;
        p = strchr(p, ',');
        if (p == NULL) {
            break;
        }
        *p++ = '\0';
    }
    return n;
}

/* Check the CSV and find the servo ids with at least one reply; -1 when it is not a log
 * CSV or holds nothing to plot. */
static int csv_scan(const char *file, uint32_t *ids, unsigned long *rows)
{
    char line[512];
    char *field[CSV_FIELDS];
    FILE *f = fopen(file, "r");
    *ids = 0;
    *rows = 0;
    if (f == NULL) {
        cli_error("cannot read %s: %s", file, strerror(errno));
        return -1;
    }
    if (fgets(line, sizeof line, f) == NULL || strncmp(line, "time_s,id,ok,pos_rad", 20) != 0) {
        cli_error("%s is not a CSV written by j288 log (header time_s,id,ok,pos_rad,...)", file);
        fclose(f);
        return -1;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        long id;
        if (split_csv(line, field) < CSV_FIELDS || strcmp(field[2], "1") != 0) {
            continue;
        }
        id = strtol(field[1], NULL, 10);
        if (id >= 0 && id <= (long)J288_MAX_ID) {
            *ids |= (uint32_t)(1ul << id);
            (*rows)++;
        }
    }
    fclose(f);
    if (*rows == 0u) {
        cli_error("%s holds no replies to plot", file);
        return -1;
    }
    return 0;
}

/* Servo id's rows as a gnuplot datablock $sID: time pos speed torque pos_des. Re-reading the
 * file per id keeps memory constant whatever the log's length. */
static int write_datablock(FILE *gp, const char *file, unsigned id)
{
    char line[512];
    char *field[CSV_FIELDS];
    FILE *f = fopen(file, "r");
    if (f == NULL) {
        return -1;
    }
    fprintf(gp, "$s%u << EOD\n", id);
    while (fgets(line, sizeof line, f) != NULL) {
        if (split_csv(line, field) < CSV_FIELDS || strcmp(field[2], "1") != 0 ||
            strtol(field[1], NULL, 10) != (long)id) {
            continue;
        }
        /* A joint angle not yet known is an empty pos_rad: a gap, not a shifted column. */
        fprintf(gp, "%s %s %s %s %s\n", field[0], field[3][0] != '\0' ? field[3] : "NaN",
                field[4], field[5],
                field[11][0] != '\0' ? field[11] : "NaN");
    }
    fprintf(gp, "EOD\n");
    fclose(f);
    return 0;
}

/* File names go into the gnuplot script between single quotes. */
static bool safe_for_gnuplot(const char *s)
{
    return strpbrk(s, "'\n\r") == NULL;
}

static void id_list(uint32_t ids, char *out, size_t len)
{
    unsigned id;
    out[0] = '\0';
    for (id = 0; id <= J288_MAX_ID; id++) {
        if ((ids & (1u << id)) != 0u) {
            size_t n = strlen(out);
            snprintf(out + n, len - n, "%s%u", n != 0u ? " " : "", id);
        }
    }
}

static int write_script(FILE *gp, const char *csv, const char *png, uint32_t ids,
                        const char *idlist)
{
    static const char *const panels[3][2] = {
        {"2", "position (rad)"}, {"3", "speed (rad/s)"}, {"4", "torque (N*m)"}};
    unsigned id;
    int p;
    for (id = 0; id <= J288_MAX_ID; id++) {
        if ((ids & (1u << id)) != 0u && write_datablock(gp, csv, id) != 0) {
            return -1;
        }
    }
    fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
                "  set terminal pngcairo size 1000,900\n"
                "} else {\n"
                "  set terminal png size 1000,900\n"
                "}\n");
    fprintf(gp, "set output '%s'\n", png);
    fprintf(gp, "set grid\nset key outside right\n");
    fprintf(gp, "set multiplot layout 3,1 title 'j288 log: %s (servos %s)'\n", csv, idlist);
    for (p = 0; p < 3; p++) {
        const char *sep = "plot ";
        fprintf(gp, "set ylabel '%s'\n", panels[p][1]);
        fprintf(gp, "%s", p == 2 ? "set xlabel 'time (s)'\n" : "unset xlabel\n");
        for (id = 0; id <= J288_MAX_ID; id++) {
            if ((ids & (1u << id)) != 0u) {
                fprintf(gp, "%s$s%u using 1:%s with lines lw 1.5 title 'servo %u'", sep, id,
                        panels[p][0], id);
                sep = ", ";
            }
        }
        if (p == 0) {
            bool first = true;
            for (id = 0; id <= J288_MAX_ID; id++) {
                if ((ids & (1u << id)) != 0u) {
                    fprintf(gp, ", $s%u using 1:5 with lines dt 2 lc rgb 'gray40' title '%s'", id,
                            first ? "commanded" : "");
                    first = false;
                }
            }
        }
        fprintf(gp, "\n");
    }
    fprintf(gp, "unset multiplot\nset output\n");
    return 0;
}

int cli_cmd_plot(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--png", true, OPT_PNG}, {NULL, false, 0}};
    const char *csv = NULL, *png = NULL, *v;
    char errfile[] = "/tmp/j288-plot.XXXXXX";
    char command[128];
    char first_err[256] = "";
    char idlist[64];
    cli_args_t a;
    uint32_t ids;
    unsigned long rows;
    struct stat st;
    FILE *gp;
    int key, fd, status;

    (void)g;
    cli_args_init(&a, argc, argv);
    while ((key = cli_args_next(&a, opts, &v)) != CLI_ARG_END) {
        if (key == CLI_ARG_HELP) {
            fputs(plot_help, stdout);
            return CLI_EXIT_OK;
        }
        if (key == CLI_ARG_ERROR) {
            return CLI_EXIT_USAGE;
        }
        if (key == OPT_PNG) {
            png = v;
        } else if (csv == NULL) {
            csv = v;
        } else {
            cli_error("unexpected argument '%s' (one CSV file per plot)", v);
            return CLI_EXIT_USAGE;
        }
    }
    if (csv == NULL || png == NULL) {
        cli_error("usage: j288 plot FILE.csv --png OUT.png");
        return CLI_EXIT_USAGE;
    }
    if (!safe_for_gnuplot(csv) || !safe_for_gnuplot(png)) {
        cli_error("file names with quotes or line breaks cannot be passed to gnuplot");
        return CLI_EXIT_USAGE;
    }
    if (csv_scan(csv, &ids, &rows) != 0) {
        return CLI_EXIT_FAIL;
    }
    if (!png_writable(png)) {
        return CLI_EXIT_FAIL;
    }
    if (!have_program("gnuplot")) {
        cli_error("gnuplot is not installed: no PNG written (apt-get install gnuplot-nox); "
                  "the CSV is %s",
                  csv);
        return CLI_EXIT_NO_TOOL;
    }
    fd = mkstemp(errfile);
    if (fd < 0) {
        cli_error("cannot create a temporary file: %s", strerror(errno));
        return CLI_EXIT_FAIL;
    }
    close(fd);
    /* stdout to /dev/null: gnuplot writes the PNG there when `set output` fails. */
    snprintf(command, sizeof command, "gnuplot >/dev/null 2>%s", errfile);
    (void)remove(png);
    gp = popen(command, "w");
    if (gp == NULL) {
        cli_error("cannot run gnuplot: %s", strerror(errno));
        remove(errfile);
        return CLI_EXIT_FAIL;
    }
    id_list(ids, idlist, sizeof idlist);
    if (write_script(gp, csv, png, ids, idlist) != 0) {
        cli_error("cannot read %s", csv);
        (void)pclose(gp);
        remove(errfile);
        return CLI_EXIT_FAIL;
    }
    status = pclose(gp);
    {
        FILE *ef = fopen(errfile, "r");
        if (ef != NULL) {
            while (fgets(first_err, sizeof first_err, ef) != NULL) {
                if (strstr(first_err, "rror") != NULL) {
                    break;
                }
            }
            fclose(ef);
        }
        remove(errfile);
    }
    if (status != 0 || stat(png, &st) != 0 || st.st_size == 0) {
        first_err[strcspn(first_err, "\n")] = '\0';
        cli_error("gnuplot failed to write %s%s%s", png, first_err[0] != '\0' ? ": " : "",
                  first_err);
        return CLI_EXIT_FAIL;
    }
    printf("plotted %lu rows (servos %s) from %s to %s\n", rows, idlist, csv, png);
    return CLI_EXIT_OK;
}
