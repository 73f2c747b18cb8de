/* j288-sim as a child process of a host test: started with fork/exec, its pty path read from
 * its first output line, stopped and reaped. The binary: $J288_SIM (make test-valgrind points
 * it at a valgrind wrapper), else J288_SIM_DEFAULT compiled in. Test code only: not
 * thread-safe, and failures end the running Unity test. */
#ifndef SIM_PROCESS_H
#define SIM_PROCESS_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#define SIM_PROCESS_MAX_ARGS 30

/* Start the simulator with args (NULL-terminated; at most SIM_PROCESS_MAX_ARGS are passed)
 * and read the pty path it prints into pty (pty_len bytes, NUL-terminated). *pid is set as
 * soon as the child exists, so a caller's tearDown can reap it even when this fails the test:
 * it does when the child cannot be made or no /dev/ path comes within 30 s. */
void sim_process_start(const char *const *args, pid_t *pid, char *pty, size_t pty_len);

/* SIGTERM to pid, SIGKILL when it has not exited 20 s later; reaps it. Its wait status, or -1
 * when pid <= 0 (nothing started). */
int sim_process_stop(pid_t pid);

/* Whether a line of the text file at path (the simulator's --log) contains needle; false when
 * the file cannot be opened. Lines longer than 255 bytes are read in pieces. */
bool sim_log_contains(const char *path, const char *needle);

#endif
