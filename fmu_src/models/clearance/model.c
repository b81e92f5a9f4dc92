/*
 * model.c: TipClearance in C behind the shared FMI wrapper (fmu_model.h): the closure of a fan's tip clearance
 * an engine's performance model would hand the contact model, from the spool speed alone
 * (fmu_src/models/clearance/variables.py states the model):
 *
 *     closure = closure0 + c_centrifugal Omega^2 + d_thermal,   tau dd_thermal/dt = c_thermal Omega^2 - d_thermal
 *
 * the centrifugal growth of disk and blades at once, the thermal growth with the lag of the casing's
 * temperature. With Omega held over a step the lag is integrated exactly (an exponential), so the model has
 * no step-size error to speak of. The outputs follow the speed held over the last step; before the first,
 * the speed Omega holds when initialisation ends (the engine's speed before the run, warm there): the spool's
 * initial speed where the master propagates its connections' initial values (libcosim, OMSimulator and the
 * project's fmpy and C masters do), else the declared start value.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "model.h"
#include "rr_math.h"

#define STATE_TAG 52170501.0

struct model_runtime {
    double closure0, cc, ct, tau;
    double t, d, w; /* time, thermal growth, the speed held over the last step */
};

static void outputs(const model_runtime *m, model_values *v)
{
    double w = m->w, c = m->cc * w * w;
    v->r[VR_CLOSURE_CENTRIFUGAL] = c;
    v->r[VR_CLOSURE_THERMAL] = m->d;
    v->r[VR_CLOSURE] = m->closure0 + c + m->d;
}

model_runtime *model_configure(const model_values *v, double t0, char *msg, size_t len)
{
    model_runtime *m = (model_runtime *)calloc(1, sizeof *m);
    if (!m) {
        snprintf(msg, len, "out of memory");
        return NULL;
    }
    m->closure0 = v->r[VR_CLOSURE0];
    m->cc = v->r[VR_C_CENTRIFUGAL];
    m->ct = v->r[VR_C_THERMAL];
    m->tau = v->r[VR_TAU_THERMAL];
    m->t = t0;
    m->w = v->r[VR_OMEGA];
    m->d = m->ct * m->w * m->w; /* warm at the initial speed: the engine ran there */
    return m;
}

void model_free(model_runtime *m) { free(m); }

model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len)
{
    double w = v->r[VR_OMEGA], target = m->ct * w * w;
    (void)msg;
    (void)len;
    m->w = w;
    m->d = target + (m->d - target) * rr_exp(-h / m->tau);
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

/* layout: tag, t, d, w */
size_t model_state_size(const model_runtime *m)
{
    (void)m;
    return 4;
}

void model_state_save(const model_runtime *m, double *out)
{
    out[0] = STATE_TAG;
    out[1] = m->t;
    out[2] = m->d;
    out[3] = m->w;
}

int model_state_restore(model_runtime *m, const double *in, size_t count)
{
    if (count != 4 || in[0] != STATE_TAG || !isfinite(in[1]) || !isfinite(in[2]) || !isfinite(in[3])) return -1;
    m->t = in[1];
    m->d = in[2];
    m->w = in[3];
    return 0;
}
