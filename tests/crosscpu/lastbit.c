/* lastbit: emulate another CPU's libm by moving the last bit of transcendental results.
 *
 * Preloaded (LD_PRELOAD) into a process, it interposes the libm functions whose
 * results differ between CPUs and libm builds (exp, log, sin, atan2, ...). Each
 * result is moved by one ulp up, one ulp down or left alone, chosen by a hash of
 * the argument bits and LASTBIT_SEED: deterministic per input, as a different
 * machine is, not random per call. Results that are integers (exp(0) = 1,
 * log(1) = 0, pow(2, 3) = 8) or not finite are left alone: every libm gets
 * those exactly. sqrt is IEEE-exact everywhere and not touched.
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
static unsigned long long n_calls = 0, n_moved = 0;

static uint64_t mix(uint64_t z) {            /* splitmix64 finaliser */
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t bits(double x) { uint64_t u; memcpy(&u, &x, sizeof u); return u; }

static double move(double r, uint64_t key) {
    n_calls++;
    if (!isfinite(r) || r == trunc(r)) return r;
    uint64_t h = mix(key ^ seed) >> 62;      /* two bits: 0, 1 keep; 2 up; 3 down */
    if (h < 2) return r;
    n_moved++;
    return nextafter(r, h == 2 ? INFINITY : -INFINITY);
}

static void report(void) {
    const char *path = getenv("LASTBIT_COUNT");
    if (!path) return;
    FILE *f = fopen(path, "a");
    if (f) { fprintf(f, "%llu %llu\n", n_moved, n_calls); fclose(f); }
}

__attribute__((constructor)) static void init(void) {
    const char *s = getenv("LASTBIT_SEED");
    if (s) seed = mix(strtoull(s, NULL, 10) + 1);
    atexit(report);
}

#define NEXT(name) static double (*real)(double) = 0; \
    if (!real) real = (double (*)(double))dlsym(RTLD_NEXT, #name)
#define NEXT2(name) static double (*real)(double, double) = 0; \
    if (!real) real = (double (*)(double, double))dlsym(RTLD_NEXT, #name)

#define WRAP1(name, tag) double name(double x) { NEXT(name); \
    return move(real(x), bits(x) * 31 + tag); }
#define WRAP2(name, tag) double name(double x, double y) { NEXT2(name); \
    return move(real(x, y), mix(bits(x)) ^ bits(y) * 131 ^ tag); }

WRAP1(exp, 1) WRAP1(expm1, 2) WRAP1(exp2, 3) WRAP1(exp10, 4)
WRAP1(log, 5) WRAP1(log1p, 6) WRAP1(log2, 7) WRAP1(log10, 8)
WRAP1(sin, 9) WRAP1(cos, 10) WRAP1(tan, 11)
WRAP1(asin, 12) WRAP1(acos, 13) WRAP1(atan, 14)
WRAP1(sinh, 15) WRAP1(cosh, 16) WRAP1(tanh, 17) WRAP1(cbrt, 18)
WRAP2(atan2, 19) WRAP2(pow, 20) WRAP2(hypot, 21)

/* compilers merge sin(x) and cos(x) into one sincos call (this file is built
 * with -fno-builtin so that it does not do so itself) */
void sincos(double x, double *s, double *c) {
    static void (*real)(double, double *, double *) = 0;
    if (!real) real = (void (*)(double, double *, double *))dlsym(RTLD_NEXT, "sincos");
    real(x, s, c);
    *s = move(*s, bits(x) * 31 + 9);       /* the tags of sin and cos: same results */
    *c = move(*c, bits(x) * 31 + 10);
}
