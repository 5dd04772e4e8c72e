/* lastbit: emulate another CPU's libm by moving the last bits of transcendental results.
 *
 * Preloaded (LD_PRELOAD) into a process, it interposes the libm functions whose
 * results differ between CPUs and libm builds (exp, log, sin, atan2, ...). Half the
 * results are left alone, the others move by k ulps, up or down, k from 1..N
 * (LASTBIT_ULPS=N, default 1), chosen by a hash of the argument bits and
 * LASTBIT_SEED: deterministic per input, as a different machine is, not random per
 * call (N = 1 is the draw this file always made). With LASTBIT_ALL=1 every result
 * moves, by k from -N..-1, 1..N. Results that are integers
 * (exp(0) = 1, log(1) = 0, pow(2, 3) = 8) or not finite are left alone: every
 * libm gets those exactly. A moved result keeps its sign and, for sin, cos and
 * tanh, stays within [-1, 1] (properties every libm keeps). sqrt is IEEE-exact
 * everywhere and not touched.
 *
 * Python's math module, numpy's scalar (non-SIMD) loops and numba-compiled code
 * all call these symbols, so all three see the perturbed results.
 * LASTBIT_COUNT=<file>: at exit, append "<moved> <calls>" to that file.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t seed = 0x9e3779b97f4a7c15ULL;
static unsigned ulps = 1;                    /* N: results move by up to N ulps */
static int all = 0;                          /* 1: every result moves (k != 0) */
static unsigned long long n_calls = 0, n_moved = 0;

static uint64_t mix(uint64_t z) {            /* splitmix64 finaliser */
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t bits(double x) { uint64_t u; memcpy(&u, &x, sizeof u); return u; }

/* r moved by k ulps drawn from the key (see above); bounded: keep |r| <= 1 */
static double move_k(double r, uint64_t key, int bounded) {
    n_calls++;
    if (!isfinite(r) || r == trunc(r)) return r;
    uint64_t h = mix(key ^ seed);
    long k;
    if (all) {                               /* -N..-1, 1..N */
        k = (long)((h >> 16) % (2 * ulps)) - (long)ulps;
        if (k >= 0) k++;
    } else {                                 /* two bits: 0, 1 keep; 2 up; 3 down ... */
        uint64_t top = h >> 62;
        if (top < 2) return r;
        k = 1 + (long)((h >> 16) % ulps);    /* ... by 1..N ulps */
        if (top == 3) k = -k;
    }
    double to = k > 0 ? INFINITY : -INFINITY, m = r;
    for (long i = 0; i < (k > 0 ? k : -k); i++) {
        double next = nextafter(m, to);
        if (!isfinite(next) || (next > 0) != (r > 0) || next == 0 || (bounded && fabs(next) > 1.0))
            break;                           /* no sign change, no overflow, |sin| <= 1 */
        m = next;
    }
    if (m != r) n_moved++;
    return m;
}

static double move(double r, uint64_t key) { return move_k(r, key, 0); }

static void report(void) {
    const char *path = getenv("LASTBIT_COUNT");
    if (!path) return;
    FILE *f = fopen(path, "a");
    if (f) { fprintf(f, "%llu %llu\n", n_moved, n_calls); fclose(f); }
}

__attribute__((constructor)) static void init(void) {
    const char *s = getenv("LASTBIT_SEED");
    if (s) seed = mix(strtoull(s, NULL, 10) + 1);
    const char *n = getenv("LASTBIT_ULPS");
    if (n && strtoul(n, NULL, 10) > 0) ulps = (unsigned)strtoul(n, NULL, 10);
    const char *a = getenv("LASTBIT_ALL");
    all = a && strcmp(a, "1") == 0;
    atexit(report);
}

#define NEXT(name) static double (*real)(double) = 0; \
    if (!real) real = (double (*)(double))dlsym(RTLD_NEXT, #name)
#define NEXT2(name) static double (*real)(double, double) = 0; \
    if (!real) real = (double (*)(double, double))dlsym(RTLD_NEXT, #name)

#define WRAP1(name, tag) double name(double x) { NEXT(name); \
    return move(real(x), bits(x) * 31 + tag); }
#define WRAPB(name, tag) double name(double x) { NEXT(name); \
    return move_k(real(x), bits(x) * 31 + tag, 1); }
#define WRAP2(name, tag) double name(double x, double y) { NEXT2(name); \
    return move(real(x, y), mix(bits(x)) ^ bits(y) * 131 ^ tag); }

WRAP1(exp, 1) WRAP1(expm1, 2) WRAP1(exp2, 3) WRAP1(exp10, 4)
WRAP1(log, 5) WRAP1(log1p, 6) WRAP1(log2, 7) WRAP1(log10, 8)
WRAPB(sin, 9) WRAPB(cos, 10) WRAP1(tan, 11)
WRAP1(asin, 12) WRAP1(acos, 13) WRAP1(atan, 14)
WRAP1(sinh, 15) WRAP1(cosh, 16) WRAPB(tanh, 17) WRAP1(cbrt, 18)
WRAP2(atan2, 19) WRAP2(pow, 20) WRAP2(hypot, 21)

/* compilers merge sin(x) and cos(x) into one sincos call (this file is built
 * with -fno-builtin so that it does not do so itself) */
void sincos(double x, double *s, double *c) {
    static void (*real)(double, double *, double *) = 0;
    if (!real) real = (void (*)(double, double *, double *))dlsym(RTLD_NEXT, "sincos");
    real(x, s, c);
    *s = move_k(*s, bits(x) * 31 + 9, 1);  /* the tags of sin and cos: same results */
    *c = move_k(*c, bits(x) * 31 + 10, 1);
}
