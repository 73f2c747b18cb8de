/* Allocation counting for tests (alloc_count.h). */
#define _GNU_SOURCE 1

#include "alloc_count.h"

#include <errno.h>
#include <stddef.h>
#include <stdint.h>

static volatile int g_counting;
static volatile unsigned long g_count;

static void counted(void)
{
    if (g_counting)
        g_count++;
}

#if defined(__SANITIZE_ADDRESS__)
#define ALLOC_COUNT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ALLOC_COUNT_ASAN 1
#endif
#endif

#ifdef ALLOC_COUNT_ASAN
/* sanitizer/allocator_interface.h (not shipped with every compiler's headers) */
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void *, size_t),
                                              void (*free_hook)(const volatile void *));

static void on_malloc(const volatile void *p, size_t n)
{
    (void)p;
    (void)n;
    counted();
}

static void on_free(const volatile void *p)
{
    (void)p;
}

static void install(void)
{
    static int installed;
    if (!installed)
        installed = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}
#else
/* glibc's allocator under its own names: replacing malloc this way is what glibc documents
 * ("Replacing malloc"); valgrind still sees every block (it replaces the __libc_* ones). */
void *__libc_malloc(size_t n);
void *__libc_calloc(size_t k, size_t n);
void *__libc_realloc(void *p, size_t n);
void __libc_free(void *p);
void *__libc_memalign(size_t align, size_t n);
void *__libc_valloc(size_t n);
void *__libc_pvalloc(size_t n);

void *malloc(size_t n)
{
    counted();
    return __libc_malloc(n);
}

void *calloc(size_t k, size_t n)
{
    counted();
    return __libc_calloc(k, n);
}

void *realloc(void *p, size_t n)
{
    counted();
    return __libc_realloc(p, n);
}

void free(void *p)
{
    __libc_free(p);
}

void *memalign(size_t align, size_t n)
{
    counted();
    return __libc_memalign(align, n);
}

void *aligned_alloc(size_t align, size_t n)
{
    counted();
    return __libc_memalign(align, n);
}

int posix_memalign(void **out, size_t align, size_t n)
{
    void *p;
    counted();
    if (align < sizeof(void *) || (align & (align - 1u)) != 0u)
        return EINVAL;
    p = __libc_memalign(align, n);
    if (p == NULL && n != 0u)
        return ENOMEM;
    *out = p;
    return 0;
}

void *valloc(size_t n)
{
    counted();
    return __libc_valloc(n);
}

void *pvalloc(size_t n)
{
    counted();
    return __libc_pvalloc(n);
}

static void install(void) {}
#endif

void alloc_count_start(void)
{
    install();
    g_count = 0;
    g_counting = 1;
}

unsigned long alloc_count_stop(void)
{
    g_counting = 0;
    return g_count;
}
