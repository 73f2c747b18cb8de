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
    "one line per servo, from a CSV written by `j288 log`, using gnuplot.\n"
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

/* The servo ids present in the CSV, as a bit mask; -1 when it is not a log CSV. */
static int csv_ids(const char *file, uint32_t *ids, unsigned long *rows)
{
    char line[512];
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
        const char *comma = strchr(line, ',');
        long id;
        if (comma == NULL) {
            continue;
        }
        id = strtol(comma + 1, NULL, 10);
        if (id >= 0 && id <= (long)J288_MAX_ID) {
            *ids |= (uint32_t)(1ul << id);
            (*rows)++;
        }
    }
    fclose(f);
    if (*rows == 0u) {
        cli_error("%s holds no rows to plot", file);
        return -1;
    }
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

static void write_script(FILE *gp, const char *csv, const char *png, const char *idlist)
{
    static const char *const panels[3][3] = {{"4", "position (rad)", "pos"},
                                             {"5", "speed (rad/s)", "speed"},
                                             {"6", "torque (N*m)", "torque"}};
    int p;
    fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
                "  set terminal pngcairo size 1000,900\n"
                "} else {\n"
                "  set terminal png size 1000,900\n"
                "}\n");
    fprintf(gp, "set output '%s'\n", png);
    fprintf(gp, "set datafile separator ','\n"
                "set datafile missing ''\n"
                "set grid\nset key outside right\n");
    fprintf(gp, "ids = '%s'\n", idlist);
    fprintf(gp, "set multiplot layout 3,1 title 'j288 log: %s'\n", csv);
    for (p = 0; p < 3; p++) {
        fprintf(gp, "set ylabel '%s'\n", panels[p][1]);
        fprintf(gp, "%s", p == 2 ? "set xlabel 'time (s)'\n" : "unset xlabel\n");
        fprintf(gp,
                "plot for [k=1:words(ids)] '%s' every ::1 using 1:((column(2) == "
                "word(ids,k)+0 && column(3) == 1) ? column(%s) : NaN) with lines lw 1.5 "
                "title sprintf('servo %%s', word(ids,k))",
                csv, panels[p][0]);
        if (p == 0) {
            fprintf(gp,
                    ", for [k=1:words(ids)] '%s' every ::1 using 1:(column(2) == "
                    "word(ids,k)+0 ? column(12) : NaN) with lines dt 2 lc rgb 'gray40' "
                    "title (k == 1 ? 'commanded' : '')",
                    csv);
        }
        fprintf(gp, "\n");
    }
    fprintf(gp, "unset multiplot\nset output\n");
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
    if (csv_ids(csv, &ids, &rows) != 0) {
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
    snprintf(command, sizeof command, "gnuplot 2>%s", errfile);
    (void)remove(png);
    gp = popen(command, "w");
    if (gp == NULL) {
        cli_error("cannot run gnuplot: %s", strerror(errno));
        remove(errfile);
        return CLI_EXIT_FAIL;
    }
    id_list(ids, idlist, sizeof idlist);
    write_script(gp, csv, png, idlist);
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
