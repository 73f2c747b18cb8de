/* j288_host_wait.c - j288_host_wait() on Linux: one ppoll() over the ports' descriptors. */
#define _GNU_SOURCE 1 /* ppoll */

#include "j288_host_wait.h"

#include <poll.h>
#include <time.h>

unsigned j288_host_wait(j288_linux_t *const ports[], unsigned n, uint32_t timeout_us,
                        bool ready[])
{
    struct pollfd pfd[J288_HOST_WAIT_MAX];
    unsigned who[J288_HOST_WAIT_MAX];
    struct timespec ts;
    nfds_t nfds = 0;
    unsigned i, got = 0;
    int rc;

    for (i = 0; i < n && i < J288_HOST_WAIT_MAX; i++) {
        int fd = j288_linux_fd(ports[i]);
        ready[i] = false;
        if (fd < 0)
            continue;
        pfd[nfds].fd = fd;
        pfd[nfds].events = POLLIN;
        pfd[nfds].revents = 0;
        who[nfds] = i;
        nfds++;
    }
    ts.tv_sec = (time_t)(timeout_us / 1000000u);
    ts.tv_nsec = (long)(timeout_us % 1000000u) * 1000L;
    rc = ppoll(pfd, nfds, &ts, NULL);
    if (rc <= 0)
        return 0; /* timeout, or a signal */
    for (i = 0; i < (unsigned)nfds; i++) {
        if (pfd[i].revents != 0) {
            ready[who[i]] = true;
            got++;
        }
    }
    return got;
}
