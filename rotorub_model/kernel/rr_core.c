/* rotorub kernel: version, source id, scratch sizes, elementary functions (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

#ifndef RR_SOURCE_ID
#define RR_SOURCE_ID "unversioned"
#endif

int rr_abi_version(void) { return RR_ABI_VERSION; }

const char *rr_source_id(void) { return RR_SOURCE_ID; }

/* scratch: gaps (nb*np) + law (nb*RR_LAW_WIDTH) + friction (nb*np) + right-hand side (n) + a block step's (n) */
int rr_work_size(int n, int nb, int np) { return nb * np + nb * RR_LAW_WIDTH + nb * np + 2 * n; }

void rr_elementary(int fn, int m, const double *x, const double *y, double *out)
{
    int i;
    for (i = 0; i < m; ++i) {
        switch (fn) {
        case RR_FN_SIN: out[i] = rr_sin(x[i]); break;
        case RR_FN_COS: out[i] = rr_cos(x[i]); break;
        case RR_FN_TAN: out[i] = rr_tan(x[i]); break;
        case RR_FN_ATAN2: out[i] = rr_atan2(x[i], y[i]); break;
        case RR_FN_TANH: out[i] = rr_tanh(x[i]); break;
        case RR_FN_EXP: out[i] = rr_exp(x[i]); break;
        case RR_FN_SQRT: out[i] = rr_sqrt(x[i]); break;
        case RR_FN_FLOOR: out[i] = rr_floor(x[i]); break;
        case RR_FN_CEIL: out[i] = rr_ceil(x[i]); break;
        default: out[i] = 0.0; break; /* unreachable from kernel.elementary(), which checks the name */
        }
    }
}
