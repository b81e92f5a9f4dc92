/*
 * rr_math.h: the elementary functions of the rotorub kernel and of the native FMUs, written in
 * IEEE 754 double arithmetic (+ - * / and the correctly rounded square root) in a fixed order.
 *
 * Why not libm: every C library has its own sin, cos, tanh, ... and they differ in the last bit
 * (glibc, the Microsoft CRT behind mingw, Apple's libm). The kernel calls tanh in every substep
 * (the friction law) and sin/cos in every output of a state, so a 1-ulp difference at step 21
 * became a 4e-12 difference of the forces in a run. These functions give the same bits on every
 * platform and compiler that honours IEEE 754 double arithmetic without contraction to FMA and
 * without reassociation (-ffp-contract=off, no -ffast-math; MSVC /fp:precise), and they need no
 * libm at all on x86_64 and aarch64, so a binary built with any CMake recipe loads without -lm.
 *
 * Accuracy (tests/test_rr_math.py, against glibc over 2e5 arguments each): sin, cos and exp within
 * 1 ulp, tan and tanh within 2, atan2 within 4 (it is only used to build the contact geometry). Method: Taylor
 * polynomials on a reduced range (coefficients 1/n!, 1/n: the truncation error is far below an
 * ulp there), Cody-Waite style reductions done exactly (error-free products and sums), and for
 * sin/cos the argument reduced by pi/2 held as three doubles (159 bits): exact enough for
 * |x| < 2^30 (a spin angle of 1e9 rad). Beyond that the results stay deterministic but lose
 * accuracy gradually. NaN in gives NaN out; infinities follow C99 Annex F where the kernel can
 * meet them.
 *
 * Everything is `static`: each translation unit that includes this header gets its own copy,
 * nothing is exported.
 */
#ifndef RR_MATH_H
#define RR_MATH_H

#include <stdint.h>
#include <string.h>

#if defined(__x86_64__) || defined(_M_X64)
#include <emmintrin.h>
#define RR_SQRT_SSE2 1
#elif defined(__aarch64__) && (defined(__GNUC__) || defined(__clang__))
#include <arm_neon.h>
#define RR_SQRT_NEON 1
#else
#include <math.h>
#endif

/* the correctly rounded square root (IEEE 754 requires it, so every route gives the same bits);
 * through the instruction on x86_64 and aarch64 so that no libm symbol is needed */
static double rr_sqrt(double x)
{
#if defined(RR_SQRT_SSE2)
    return _mm_cvtsd_f64(_mm_sqrt_sd(_mm_set_sd(x), _mm_set_sd(x)));
#elif defined(RR_SQRT_NEON)
    return vget_lane_f64(vsqrt_f64(vdup_n_f64(x)), 0);
#else
    return sqrt(x);
#endif
}

static double rr_fabs(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u &= 0x7fffffffffffffffULL;
    memcpy(&x, &u, sizeof u);
    return x;
}

/* 2^k for -1074 <= k <= 1023 (k an integer) */
static double rr_pow2(int k)
{
    uint64_t u;
    double x;
    if (k < -1022) return rr_pow2(k + 54) * 5.5511151231257827e-17; /* 2^-54: subnormal results */
    u = (uint64_t)(k + 1023) << 52;
    memcpy(&x, &u, sizeof u);
    return x;
}

#define RR_TWO52 4503599627370496.0

static double rr_floor(double v)
{
    double t;
    if (!(rr_fabs(v) < RR_TWO52)) return v; /* already integral (or NaN, inf) */
    /* adding and removing 2^52 rounds to the nearest integer (the spacing there is 1) */
    t = v >= 0.0 ? (v + RR_TWO52) - RR_TWO52 : (v - RR_TWO52) + RR_TWO52;
    if (t > v) t -= 1.0;
    return t + 0.0; /* -0.0 -> +0.0 is harmless here; keeps results of floor(-0.0) uniform */
}

static double rr_ceil(double v) { return -rr_floor(-v); }

/* the nearest integer (ties either way: only a reduction's choice of multiple) */
static double rr_nearest(double v)
{
    if (!(rr_fabs(v) < RR_TWO52)) return v;
    return v >= 0.0 ? (v + RR_TWO52) - RR_TWO52 : (v - RR_TWO52) + RR_TWO52;
}

/* error-free transformations: a + b = s + e, a * b = p + e exactly (Knuth, Dekker; no FMA) */
static void rr_two_sum(double a, double b, double *s, double *e)
{
    double x = a + b, bb = x - a;
    *e = (a - (x - bb)) + (b - bb);
    *s = x;
}

static void rr_two_prod(double a, double b, double *p, double *e)
{
    const double split = 134217729.0; /* 2^27 + 1 */
    double x = a * b, t, ah, al, bh, bl;
    t = split * a;
    ah = t - (t - a);
    al = a - ah;
    t = split * b;
    bh = t - (t - b);
    bl = b - bh;
    *e = ((ah * bh - x) + ah * bl + al * bh) + al * bl;
    *p = x;
}

/* pi/2 = PIO2_1 + PIO2_2 + PIO2_3 (each the nearest double to what is left) */
#define RR_PIO2_1 1.5707963267948966
#define RR_PIO2_2 6.123233995736766e-17
#define RR_PIO2_3 -1.4973849048591698e-33
#define RR_PI 3.141592653589793
#define RR_PI_LO 1.2246467991473532e-16
#define RR_PIO4 0.7853981633974483
#define RR_PIO4_LO 3.061616997868383e-17
#define RR_TWO_OVER_PI 0.6366197723675814

/* x = k pi/2 + (hi + lo), |hi| <= pi/4 (slightly more at rounding ties); returns k mod 4 */
static int rr_reduce_pio2(double x, double *hi, double *lo)
{
    double k, p1, e1, p2, e2, h, l, t, q;
    if (rr_fabs(x) <= RR_PIO4) {
        *hi = x;
        *lo = 0.0;
        return 0;
    }
    k = rr_nearest(x * RR_TWO_OVER_PI);
    rr_two_prod(k, RR_PIO2_1, &p1, &e1);
    rr_two_prod(k, RR_PIO2_2, &p2, &e2);
    /* r = x - p1 - e1 - p2 - e2 - k PIO2_3: the large terms through exact sums, only the small ones rounded */
    rr_two_sum(x, -p1, &h, &l);
    rr_two_sum(h, -e1, &h, &t);
    l += t;
    rr_two_sum(h, -p2, &h, &t);
    l += t;
    l -= e2 + k * RR_PIO2_3;
    rr_two_sum(h, l, hi, lo);
    q = k - 4.0 * rr_floor(k * 0.25); /* 0, 1, 2 or 3 */
    return (int)q;
}

/* sin and cos of hi + lo, |hi| <= pi/4 + a little, |lo| <= ulp(hi) */
static double rr_sin_kernel(double x, double y)
{
    double z = x * x;
    double p = -0.16666666666666666 +
               z * (0.008333333333333333 +
                    z * (-0.0001984126984126984 +
                         z * (2.7557319223985893e-06 +
                              z * (-2.505210838544172e-08 +
                                   z * (1.6059043836821613e-10 +
                                        z * (-7.647163731819816e-13 + z * 2.8114572543455206e-15))))));
    /* sin(x + y) = sin x + y cos x, cos x = 1 - z/2 to the order kept */
    return x + (x * z * p + y * (1.0 - 0.5 * z));
}

static double rr_cos_kernel(double x, double y)
{
    double z = x * x, hz = 0.5 * z, w = 1.0 - hz;
    double p = 0.041666666666666664 +
               z * (-0.001388888888888889 +
                    z * (2.48015873015873e-05 +
                         z * (-2.755731922398589e-07 +
                              z * (2.08767569878681e-09 +
                                   z * (-1.1470745597729725e-11 +
                                        z * (4.779477332387385e-14 + z * -1.5619206968586225e-16))))));
    /* cos(x + y) = cos x - y sin x; ((1 - w) - hz) is the rounding error of w, recovered */
    return w + (((1.0 - w) - hz) + (z * z * p - x * y));
}

static double rr_sin(double x)
{
    double h, l;
    int q;
    if (x - x != 0.0) return x - x; /* NaN, inf -> NaN */
    if (rr_fabs(x) < 3.725290298461914e-09) return x; /* 2^-28: sin x = x to the last bit (and -0 stays -0) */
    q = rr_reduce_pio2(x, &h, &l);
    switch (q) {
    case 0: return rr_sin_kernel(h, l);
    case 1: return rr_cos_kernel(h, l);
    case 2: return -rr_sin_kernel(h, l);
    default: return -rr_cos_kernel(h, l);
    }
}

static double rr_cos(double x)
{
    double h, l;
    int q;
    if (x - x != 0.0) return x - x;
    q = rr_reduce_pio2(x, &h, &l);
    switch (q) {
    case 0: return rr_cos_kernel(h, l);
    case 1: return -rr_sin_kernel(h, l);
    case 2: return -rr_cos_kernel(h, l);
    default: return rr_sin_kernel(h, l);
    }
}

static void rr_sincos(double x, double *s, double *c)
{
    double h, l, sk, ck;
    int q;
    if (x - x != 0.0) {
        *s = *c = x - x;
        return;
    }
    q = rr_reduce_pio2(x, &h, &l);
    sk = rr_sin_kernel(h, l);
    ck = rr_cos_kernel(h, l);
    switch (q) {
    case 0: *s = sk; *c = ck; break;
    case 1: *s = ck; *c = -sk; break;
    case 2: *s = -sk; *c = -ck; break;
    default: *s = -ck; *c = sk; break;
    }
}

static double rr_tan(double x)
{
    double s, c;
    rr_sincos(x, &s, &c);
    return s / c;
}

/* e^x = 2^k e^r, x = k ln2 + r, |r| <= ln2 / 2; ln2 = LN2_HI + LN2_LO, LN2_HI with 42 bits so k LN2_HI is exact */
#define RR_LN2_HI 0.6931471805598903
#define RR_LN2_LO 5.497923018708371e-14
#define RR_INV_LN2 1.4426950408889634

/* e^r - 1 for |r| <= 0.35 (Taylor to r^13: the rest is below 5e-18 relative) */
static double rr_expm1_small(double r)
{
    double q = 0.5 +
               r * (0.16666666666666666 +
                    r * (0.041666666666666664 +
                         r * (0.008333333333333333 +
                              r * (0.001388888888888889 +
                                   r * (0.0001984126984126984 +
                                        r * (2.48015873015873e-05 +
                                             r * (2.7557319223985893e-06 +
                                                  r * (2.755731922398589e-07 +
                                                       r * (2.505210838544172e-08 +
                                                            r * (2.08767569878681e-09 +
                                                                 r * 1.6059043836821613e-10))))))))));
    return r + r * r * q;
}

static double rr_exp(double x)
{
    double k, r;
    if (x != x) return x;
    if (x > 709.782712893384) {
        double big = 1e300;
        return big * big; /* overflow: +inf */
    }
    if (x < -745.1332191019412) return 0.0;
    k = rr_nearest(x * RR_INV_LN2);
    r = (x - k * RR_LN2_HI) - k * RR_LN2_LO;
    return (1.0 + rr_expm1_small(r)) * rr_pow2((int)k);
}

/* e^x - 1 for |x| <= 1.1 (Taylor to x^20: the rest is below 3e-18 relative): no cancellation */
static double rr_expm1_medium(double r)
{
    double q = 0.5 + r * (0.16666666666666666 + r * (0.041666666666666664 + r * (0.008333333333333333 + r * (
        0.001388888888888889 + r * (0.0001984126984126984 + r * (2.48015873015873e-05 + r * (2.7557319223985893e-06 +
        r * (2.755731922398589e-07 + r * (2.505210838544172e-08 + r * (2.08767569878681e-09 + r * (
        1.6059043836821613e-10 + r * (1.1470745597729725e-11 + r * (7.647163731819816e-13 + r * (
        4.779477332387385e-14 + r * (2.8114572543455206e-15 + r * (1.5619206968586225e-16 + r * (
        8.22063524662433e-18 + r * 4.110317623312165e-19)))))))))))))))));
    return r + r * r * q;
}

static double rr_expm1(double x)
{
    if (rr_fabs(x) <= 1.1) return rr_expm1_medium(x);
    return rr_exp(x) - 1.0;
}

static double rr_tanh(double x)
{
    double a = rr_fabs(x), t;
    if (x != x) return x;
    if (a > 22.0) return x > 0.0 ? 1.0 : -1.0; /* 1 - tanh(22) < 2^-60 */
    if (a < 3.725290298461914e-09) return x;  /* 2^-28: tanh x = x to the last bit */
    if (a < 0.55) {
        double e = rr_expm1_medium(2.0 * a), d, err;
        rr_two_sum(e, 2.0, &d, &err); /* e + 2 = d + err exactly: the division then sees no rounding of it */
        t = e / d;
        t = t - t * (err / d);
    } else {
        t = 1.0 - 2.0 / (rr_exp(2.0 * a) + 1.0); /* >= 0.5: the subtraction loses nothing */
    }
    return x > 0.0 ? t : -t;
}

/* atan t for 0 <= t <= 1 */
static double rr_atan_unit(double t)
{
    double base = 0.0, base_lo = 0.0, v, z, p;
    if (t > 0.41421356237309503) { /* tan(pi/8): atan t = pi/4 + atan((t - 1) / (t + 1)) */
        t = (t - 1.0) / (t + 1.0);
        base = RR_PIO4;
        base_lo = RR_PIO4_LO;
    }
    /* atan u = 2 atan(u / (1 + sqrt(1 + u^2))): |v| <= tan(pi/16) ~ 0.199 */
    v = t / (1.0 + rr_sqrt(1.0 + t * t));
    z = v * v;
    p = -0.3333333333333333 +
        z * (0.2 +
             z * (-0.14285714285714285 +
                  z * (0.1111111111111111 +
                       z * (-0.09090909090909091 +
                            z * (0.07692307692307693 +
                                 z * (-0.06666666666666667 +
                                      z * (0.058823529411764705 +
                                           z * (-0.05263157894736842 +
                                                z * (0.047619047619047616 + z * -0.043478260869565216)))))))));
    return base + (2.0 * (v + v * z * p) + base_lo);
}

static double rr_atan2(double y, double x)
{
    double ax = rr_fabs(x), ay = rr_fabs(y), a;
    int ypos;
    uint64_t uy;
    if (x != x || y != y) return x + y;
    memcpy(&uy, &y, sizeof uy);
    ypos = (uy >> 63) == 0;
    if (ay == 0.0 && ax == 0.0) {
        uint64_t ux;
        memcpy(&ux, &x, sizeof ux);
        a = (ux >> 63) ? RR_PI : 0.0; /* atan2(+-0, -0) = +-pi, atan2(+-0, +0) = +-0 */
        return ypos ? a : -a;
    }
    if (ax - ax != 0.0 || ay - ay != 0.0) { /* an infinity */
        if (ax - ax != 0.0 && ay - ay != 0.0) a = x > 0.0 ? RR_PIO4 : 3.0 * RR_PIO4;
        else if (ay - ay != 0.0) a = 2.0 * RR_PIO4;
        else a = x > 0.0 ? 0.0 : RR_PI;
        return ypos ? a : -a;
    }
    if (ay > ax) /* pi/2 - atan(ax/ay) */
        a = (2.0 * RR_PIO4 - rr_atan_unit(ax / ay)) + 2.0 * RR_PIO4_LO;
    else
        a = rr_atan_unit(ay / ax);
    if (x < 0.0) a = (RR_PI - a) + RR_PI_LO;
    return ypos ? a : -a;
}

#endif
