/*
 * write_stamp.so - for scripts/bench-dds.sh only (LD_PRELOAD into j288-dds): every write() of
 * a 20-byte J288 command frame (head 0xFE 0xEE) is logged to $J288_WRITE_STAMP as
 * 'MONOTONIC_NS FD HEX' just before it goes to the kernel, i.e. as the frame leaves for the bus.
 * Not part of any product or test; glibc's dlsym(RTLD_NEXT) finds the real write().
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

typedef ssize_t (*write_fn)(int, const void *, size_t);

ssize_t write(int fd, const void *buf, size_t len)
{
    static write_fn real;
    static FILE *log;
    const unsigned char *b = buf;
    if (real == NULL) {
        const char *path = getenv("J288_WRITE_STAMP");
        real = (write_fn)(size_t)dlsym(RTLD_NEXT, "write");
        if (path != NULL)
            log = fopen(path, "w");
    }
    if (log != NULL && len == 20u && b[0] == 0xFEu && b[1] == 0xEEu) {
        struct timespec ts;
        size_t i;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        fprintf(log, "%lld %d ", (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec, fd);
        for (i = 0; i < len; i++)
            fprintf(log, "%02x", b[i]);
        fputc('\n', log);
    }
    return real(fd, buf, len);
}
