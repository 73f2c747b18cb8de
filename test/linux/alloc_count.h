/* Counting the allocations a piece of code makes, for the tests that promise none (the
 * runner's cycle and its pacing: j288_robot.h). Linked into a test binary, it replaces
 * malloc and its family (each forwards to glibc's __libc_* allocator) and counts every call
 * between alloc_count_start() and alloc_count_stop(), glibc's own internal ones included;
 * built with AddressSanitizer, it counts through ASan's allocator hooks instead (ASan owns
 * malloc there). Test code only: not thread-safe. */
#ifndef ALLOC_COUNT_H
#define ALLOC_COUNT_H

void alloc_count_start(void);
/* The allocations counted since alloc_count_start(). */
unsigned long alloc_count_stop(void);

#endif
