/* j288-sim as a child process of a host test (see sim_process.h). */
#define _GNU_SOURCE 1

#include "sim_process.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "unity.h"

#ifndef J288_SIM_DEFAULT
#define J288_SIM_DEFAULT "build/bin/j288-sim"
#endif

static const char *sim_path(void)
{
    const char *p = getenv("J288_SIM");
    return (p != NULL && *p != '\0') ? p : J288_SIM_DEFAULT;
}

/* The first line from fd (up to 30 s for each byte), NUL-terminated in line. */
static void read_first_line(int fd, char *line, size_t len)
{
    size_t got = 0;
    struct pollfd pfd;
    pfd.fd = fd;
    pfd.events = POLLIN;
    while (got + 1u < len) {
        ssize_t r;
        if (poll(&pfd, 1, 30000) <= 0)
            break;
        r = read(fd, line + got, 1);
        if (r <= 0 || line[got] == '\n')
            break;
        got++;
    }
    line[got] = '\0';
}

void sim_process_start(const char *const *args, pid_t *pid, char *pty, size_t pty_len)
{
    const char *argv[SIM_PROCESS_MAX_ARGS + 2];
    int n = 0, fds[2];

    argv[n++] = sim_path();
    while (args != NULL && *args != NULL && n <= SIM_PROCESS_MAX_ARGS)
        argv[n++] = *args++;
    argv[n] = NULL;
    TEST_ASSERT_EQUAL_INT(0, pipe(fds));
    *pid = fork();
    TEST_ASSERT_TRUE(*pid >= 0);
    if (*pid == 0) {
        (void)dup2(fds[1], 1);
        (void)close(fds[0]);
        (void)close(fds[1]);
        execv(argv[0], (char *const *)argv);
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    (void)close(fds[1]);
    read_first_line(fds[0], pty, pty_len);
    (void)close(fds[0]);
    if (strncmp(pty, "/dev/", 5) != 0)
        TEST_FAIL_MESSAGE("j288-sim did not print its pty path (is it built?)");
}

int sim_process_stop(pid_t pid)
{
    int status = -1, i;
    if (pid <= 0)
        return -1;
    (void)kill(pid, SIGTERM);
    for (i = 0; i < 2000; i++) {
        if (waitpid(pid, &status, WNOHANG) == pid)
            return status;
        usleep(10000);
    }
    (void)kill(pid, SIGKILL);
    (void)waitpid(pid, &status, 0);
    return status;
}

bool sim_log_contains(const char *path, const char *needle)
{
    char line[256];
    bool found = false;
    FILE *f = fopen(path, "r");
    if (f == NULL)
        return false;
    while (!found && fgets(line, sizeof line, f) != NULL)
        found = strstr(line, needle) != NULL;
    fclose(f);
    return found;
}
