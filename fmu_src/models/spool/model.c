/*
 * model.c: LPSpool in C behind the same FMI wrapper as the contact model (fmu_model.h): the speed of a
 * turbofan's low-pressure spool, J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque
 * (fmu_src/models/spool/variables.py states the model; slave.py next to this file is the same model written as
 * a pythonfmu slave, the example of a slave in Python).
 *
 * The state is the deviation e = Omega - Omega_s(t) from the speed schedule, advanced by classical RK4 in
 * n = ceil(h / dt_max) equal substeps with friction_torque held: with no external torque every RK4 stage
 * is exactly 0 and the spool follows the schedule to the last bit.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>

#include "model.h"
#include "rr_math.h"

#define STATE_TAG 52170401.0
#define PI 3.141592653589793

struct model_runtime {
    double J, cw, w0, w1, t0, tr, dt_max;
    double t, e;
};

/* Omega_s(t) and its derivative */
static void schedule(const model_runtime *m, double t, double *ws, double *wsd)
{
    double x = (t - m->t0) / m->tr, d = m->w1 - m->w0;
    if (!(x > 0.0)) { /* before the start (also NaN) */
        *ws = m->w0;
        *wsd = 0.0;
    } else if (x >= 1.0) {
        *ws = m->w1;
        *wsd = 0.0;
    } else {
        double s, c;
        rr_sincos(PI * x, &s, &c);
        *ws = m->w0 + 0.5 * d * (1.0 - c);
        *wsd = 0.5 * d * PI / m->tr * s;
    }
}

static void outputs(const model_runtime *m, model_values *v)
{
    double ws, wsd, w;
    schedule(m, m->t, &ws, &wsd);
    w = ws + m->e;
    v->r[VR_OMEGA] = w;
    v->r[VR_OMEGA_SCHEDULE] = ws;
    v->r[VR_DRIVE_TORQUE] = m->J * wsd + m->cw * ws * ws;
    v->r[VR_WINDAGE_TORQUE] = m->cw * w * w;
}

model_runtime *model_configure(const model_values *v, double t0, char *msg, size_t len)
{
    model_runtime *m = (model_runtime *)calloc(1, sizeof *m);
    if (!m) {
        snprintf(msg, len, "out of memory");
        return NULL;
    }
    m->J = v->r[VR_J];
    m->cw = v->r[VR_C_W];
    m->w0 = v->r[VR_OMEGA0];
    m->w1 = v->r[VR_OMEGA1];
    m->t0 = v->r[VR_T_RAMP_START];
    m->tr = v->r[VR_T_RAMP];
    m->dt_max = v->r[VR_DT_MAX];
    m->t = t0;
    m->e = 0.0;
    return m;
}

void model_free(model_runtime *m) { free(m); }

static double rhs(const model_runtime *m, double s, double e, double tau)
{
    double ws, wsd;
    schedule(m, s, &ws, &wsd);
    return (tau - m->cw * e * (2.0 * ws + e)) / m->J;
}

model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len)
{
    double tau = v->r[VR_FRICTION_TORQUE], e = m->e, ds, ws, wsd, w;
    double nd = rr_ceil(h / m->dt_max * (1.0 - 1e-12));
    int n, i;
    if (!(nd <= MODEL_MAX_SUBSTEPS)) {
        char bh[32], bd[32], bt[32];
        snprintf(msg, len, "communication step h = %s s needs %.0f substeps of at most dt_max = %s s; at most %d are "
                 "taken in one step (h <= %s s); step refused, state unchanged", core_num(h, bh, sizeof bh), nd,
                 core_num(m->dt_max, bd, sizeof bd), MODEL_MAX_SUBSTEPS,
                 core_num(MODEL_MAX_SUBSTEPS * m->dt_max, bt, sizeof bt));
        return MODEL_ERROR;
    }
    n = nd < 1.0 ? 1 : (int)nd;
    ds = h / n;
    m->t = t;
    for (i = 0; i < n; ++i) {
        double s = t + i * ds, k1, k2, k3, k4;
        k1 = rhs(m, s, e, tau);
        k2 = rhs(m, s + 0.5 * ds, e + 0.5 * ds * k1, tau);
        k3 = rhs(m, s + 0.5 * ds, e + 0.5 * ds * k2, tau);
        k4 = rhs(m, s + ds, e + ds * k3, tau);
        e = e + ds / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    schedule(m, t + h, &ws, &wsd);
    w = ws + e;
    if (!isfinite(w) || w < 0.0) {
        v->i[MODEL_INFO.vr_status] = STATUS_DIVERGED; /* 1: the spool stopped */
        char bw[32], bt[32];
        snprintf(msg, len, "the spool would stop (Omega = %s rad/s at the end of the step, friction_torque = %s N.m); "
                 "step refused, state unchanged", core_num(w, bw, sizeof bw), core_num(tau, bt, sizeof bt));
        return MODEL_DISCARD;
    }
    m->e = e;
    m->t = t + h;
    v->i[MODEL_INFO.vr_status] = STATUS_OK;
    outputs(m, v);
    return MODEL_OK;
}

model_status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len)
{
    (void)msg;
    (void)len;
    m->t = t;
    outputs(m, v);
    return MODEL_OK;
}

/* layout: tag, t, e */
size_t model_state_size(const model_runtime *m)
{
    (void)m;
    return 3;
}

void model_state_save(const model_runtime *m, double *out)
{
    out[0] = STATE_TAG;
    out[1] = m->t;
    out[2] = m->e;
}

int model_state_restore(model_runtime *m, const double *in, size_t count)
{
    if (count != 3 || in[0] != STATE_TAG || !isfinite(in[1]) || !isfinite(in[2])) return -1;
    m->t = in[1];
    m->e = in[2];
    return 0;
}
