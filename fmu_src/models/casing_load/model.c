/*
 * model.c: CasingLoad in C behind the shared FMI wrapper (fmu_model.h): the engine side's distortion of the fan
 * case during a manoeuvre (fmu_src/models/casing_load/variables.py states the model and FMU.md its reasons):
 *
 *     n(t) = 1 + (load_factor_peak - 1) s(t),  s a trapezoid in time with half-cosine edges,
 *     casing_lobe2.amplitude = ovalization_per_g (n - 1),  casing_lobe2.phase = ovalization_phase,
 *     casing_offset = offset_per_g (n - 1) (cos offset_angle, sin offset_angle).
 *
 * No state but time: the outputs at a communication point are the closed form there (after a step over
 * [t, t + h], at t + h; before the first, at the start time), so a master's step size changes nothing but
 * where the schedule is sampled. No input.
 *
 * The time is the model's own compensated sum of the steps (Neumaier), not the wrapper's plain one: after 5000
 * steps of 1 ms a plain sum is 5e-13 s off k h, which the steepest edge turns into 1e-12 of the load factor; the
 * compensated sum is the steps' exact sum to the last bit, the closed form at k h to round-off. A step or a
 * solve at a time further than round-off from it (a master that restarts elsewhere) takes that time instead.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "model.h"
#include "rr_math.h"

#define STATE_TAG 52170601.0
#define PI 3.141592653589793

struct model_runtime {
    double n_peak, t0, tr, th, tf, oval, phase, off, cos_off, sin_off;
    double t, dt; /* time: the sum t and its compensation dt (the time is t + dt) */
};

/* the model's time follows the wrapper's t unless they agree to round-off (then its own, more exact, is kept) */
static void sync_time(model_runtime *m, double t)
{
    double now = m->t + m->dt;
    if (!(fabs(t - now) <= 1e-9 * (fabs(t) > 1.0 ? fabs(t) : 1.0))) {
        m->t = t;
        m->dt = 0.0;
    }
}

/* t += h, compensated (Neumaier): dt collects what the rounding of each sum dropped */
static void advance(model_runtime *m, double h)
{
    double s = m->t + h;
    m->dt += fabs(m->t) >= fabs(h) ? (m->t - s) + h : (h - s) + m->t;
    m->t = s;
}

/* s(t): 0 before t0, a half-cosine rise over tr, 1 over th, a half-cosine fall over tf, 0 after. A zero-length
 * edge is a step: its branch is never entered (t0 <= t < t0 + 0 is empty), so there is no division by zero. */
static double schedule(const model_runtime *m, double t)
{
    double t1 = m->t0 + m->tr, t2 = t1 + m->th, t3 = t2 + m->tf;
    if (!(t >= m->t0) || t >= t3) return 0.0; /* before (also NaN) and after */
    if (t < t1) return 0.5 * (1.0 - rr_cos(PI * (t - m->t0) / m->tr));
    if (t <= t2) return 1.0;
    return 0.5 * (1.0 + rr_cos(PI * (t - t2) / m->tf));
}

static void outputs(const model_runtime *m, model_values *v)
{
    double s = schedule(m, m->t + m->dt), dn = (m->n_peak - 1.0) * s;
    v->r[VR_SCHEDULE] = s;
    v->r[VR_LOAD_FACTOR] = 1.0 + dn;
    v->r[VR_CASING_LOBE2_AMPLITUDE] = m->oval * dn;
    v->r[VR_CASING_LOBE2_PHASE] = m->phase;
    v->r[VR_CASING_OFFSET_X] = m->off * dn * m->cos_off;
    v->r[VR_CASING_OFFSET_Y] = m->off * dn * m->sin_off;
}

model_runtime *model_configure(const model_values *v, double t0, char *msg, size_t len)
{
    model_runtime *m = (model_runtime *)calloc(1, sizeof *m);
    if (!m) {
        snprintf(msg, len, "out of memory");
        return NULL;
    }
    m->n_peak = v->r[VR_LOAD_FACTOR_PEAK];
    m->t0 = v->r[VR_T_START];
    m->tr = v->r[VR_T_RISE];
    m->th = v->r[VR_T_HOLD];
    m->tf = v->r[VR_T_FALL];
    m->oval = v->r[VR_OVALIZATION_PER_G];
    m->phase = v->r[VR_OVALIZATION_PHASE];
    m->off = v->r[VR_OFFSET_PER_G];
    rr_sincos(v->r[VR_OFFSET_ANGLE], &m->sin_off, &m->cos_off);
    m->t = t0;
    m->dt = 0.0;
    return m;
}

void model_free(model_runtime *m) { free(m); }

model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len)
{
    (void)msg;
    (void)len;
    sync_time(m, t);
    advance(m, h);
    v->i[MODEL_INFO.vr_status] = STATUS_OK;
    outputs(m, v);
    return MODEL_OK;
}

model_status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len)
{
    (void)msg;
    (void)len;
    sync_time(m, t);
    outputs(m, v);
    return MODEL_OK;
}

/* layout: tag, t, dt */
size_t model_state_size(const model_runtime *m)
{
    (void)m;
    return 3;
}

void model_state_save(const model_runtime *m, double *out)
{
    out[0] = STATE_TAG;
    out[1] = m->t;
    out[2] = m->dt;
}

int model_state_restore(model_runtime *m, const double *in, size_t count)
{
    if (count != 3 || in[0] != STATE_TAG || !isfinite(in[1]) || !isfinite(in[2])) return -1;
    m->t = in[1];
    m->dt = in[2];
    return 0;
}
