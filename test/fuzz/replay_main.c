/*
 * Corpus replay: runs a fuzz target's LLVMFuzzerTestOneInput() over every file of its corpus
 * without libFuzzer, so that `make test` (and the sanitizer, valgrind, big-endian and 32-bit
 * builds) re-check the targets' invariants on the committed seeds and on every crash input
 * ever saved as a regression seed. Arguments: files or directories; with none, the corpus
 * directory compiled in as FUZZ_CORPUS_DIR (a path relative to the repository root).
 */
#define _POSIX_C_SOURCE 200809L
#define _FILE_OFFSET_BITS 64 /* stat() on 32-bit hosts with 64-bit inode numbers */

#include "fuzz_common.h"

#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

#ifndef FUZZ_CORPUS_DIR
#error "FUZZ_CORPUS_DIR must name the target's corpus directory"
#endif

#define MAX_INPUT (1u << 20)

static unsigned long n_inputs;

static int run_file(const char *path)
{
    static uint8_t buf[MAX_INPUT];
    size_t n;
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "replay: cannot open %s\n", path);
        return 1;
    }
    n = fread(buf, 1u, sizeof buf, f);
    fclose(f);
    (void)LLVMFuzzerTestOneInput(buf, n); /* aborts on a broken invariant */
    n_inputs++;
    return 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Files of a directory in name order, so that runs are reproducible. */
static int run_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char *names[8192];
    size_t count = 0u, i;
    int bad = 0;
    if (d == NULL) {
        fprintf(stderr, "replay: cannot open directory %s\n", dir);
        return 1;
    }
    while ((e = readdir(d)) != NULL && count < sizeof names / sizeof names[0]) {
        size_t len;
        if (e->d_name[0] == '.') {
            continue;
        }
        len = strlen(dir) + strlen(e->d_name) + 2u;
        names[count] = malloc(len);
        if (names[count] == NULL) {
            closedir(d);
            return 1;
        }
        snprintf(names[count], len, "%s/%s", dir, e->d_name);
        count++;
    }
    closedir(d);
    qsort(names, count, sizeof names[0], cmp_names);
    for (i = 0u; i < count; i++) {
        struct stat sb;
        if (stat(names[i], &sb) == 0 && S_ISREG(sb.st_mode)) {
            bad |= run_file(names[i]);
        }
        free(names[i]);
    }
    return bad;
}

static int run_path(const char *path)
{
    struct stat sb;
    if (stat(path, &sb) != 0) {
        fprintf(stderr, "replay: no such file or directory: %s\n", path);
        return 1;
    }
    return S_ISDIR(sb.st_mode) ? run_dir(path) : run_file(path);
}

int main(int argc, char **argv)
{
    int bad = 0;
    int i;
    if (argc < 2) {
        bad = run_path(FUZZ_CORPUS_DIR);
    }
    for (i = 1; i < argc; i++) {
        bad |= run_path(argv[i]);
    }
    /* A Unity-style summary line, which scripts/run-tests.sh shows. */
    printf("%lu Tests %d Failures 0 Ignored\n%s\n", n_inputs, bad, bad ? "FAIL" : "OK");
    return (bad != 0 || n_inputs == 0u) ? 1 : 0;
}
