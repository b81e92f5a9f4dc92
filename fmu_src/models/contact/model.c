/*
 * model.c: RotorCasingContact in C, around the rotorub kernel. The same steps as the pythonfmu slave
 * (fmu_src/models/contact/slave.py) and the library, in the same order of operations,
 * so that the three give the same numbers:
 *
 *   transient     a step h is n = ceil(h / cap) kernel substeps, cap = min(dt_max, half the
 *                 central-difference stability limit with every contact closed at Omega rounded
 *                 up to a whole rad/s); the kernel writes every output of the final state;
 *   quasi_static  the kernel's balanced static solution at the held inputs (warm-started from
 *                 the last one) and the largest real part of the eigenvalues of eq. (11).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "rr_math.h"

#define RE_TOL 1e-6 /* a real part below this is a neutral mode's round-off (rotorub_model.analyses.stability) */
#define STATE_TAG 52170301.0

struct model_runtime {
    int formulation, mode, n, nb, np;
    int nk, rows; /* the kernel's 'blades' (an imported tip's segments, else nb) and the liner's rows */
    double g0, k_r, mu, theta, chord, dt_max, max_pen, v_slip;
    rr_geometry geo;
    double *geo_mem, *cwork, *cache;
    rr_contact contact;
    /* transient */
    double *q, *qp;
    rr_cd_state st;
    rr_cd_matrices mats;
    rr_cd_job job;
    double *Ainv, *K2, *Cm1, *f, *mwork;
    int *piv;
    rr_cd_blocks blocks; /* the step by blocks (MODEL_DATA.blk_nb > 0), its store and scratch */
    double *blk_store, *blk_work;
    int *blk_piv;
    int have_mats;
    double mats_omega, mats_dt;
    double plan_h, plan_band, lim_band, lim;
    int plan_n, have_plan, have_lim;
    /* quasi-static */
    double *qs, *Kw, *Fw, *swork, *Aeig, *Minv, *wr, *wi, *ework, *Jv;
    int *siwork;
    int have_qs;
    double phi_qs;
    double advanced;
    /* the casing's surface (transient mode): the liner's cells and the engine's inputs */
    rr_surface surf;
    double *surf_mem;
    double cell_area; /* m^2: arc at the tip radius times the band the tips sweep (chord cos stagger) */
    double wear[RR_WEAR_OUT]; /* the liner's summary, recomputed only when a cell was cut (720 cells x 8 harmonics
                               * every step would cost more than the step) */
    int have_wear;
};

static void *zalloc(size_t n, size_t size) { return calloc(n ? n : 1, size); }

void model_free(model_runtime *m)
{
    if (!m) return;
    free(m->geo_mem);
    free(m->q);
    free(m->Ainv);
    free(m->piv);
    free(m->qs);
    free(m->siwork);
    free(m->surf_mem);
    free(m->blk_store);
    free(m);
}

/* K(Omega) and the explicit step limit are the kernel's (rr_k_omega, rr_critical_step): the library calls the same */
static double critical_step(model_runtime *m, double w)
{
    const model_data *d = &MODEL_DATA;
    rr_k_omega(m->n, d->K, d->S2, d->N2, d->C1, d->S4, w, m->Kw);
    return rr_critical_step(&m->contact, w, m->Minv, m->Kw, m->Aeig); /* Aeig: 4 n^2 of scratch */
}

model_runtime *model_configure(const model_values *v, double t0, char *msg, size_t len)
{
    const model_data *d = &MODEL_DATA;
    model_runtime *m;
    rr_geometry_spec spec;
    const model_geometry *bg;
    int n = d->n, nb = d->nb, np, P;
    size_t nn = (size_t)n * n, off = 0;
    double *g;
    (void)t0; /* the contact model is autonomous: its state does not depend on the start time */
    if (v->r[VR_G0] < -v->r[VR_MAX_PENETRATION]) {
        snprintf(msg, len, "g0 = %.6g mm: an interference deeper than max_penetration = %.6g mm; the run would "
                 "diverge at t = 0 (accepted: g0 >= -max_penetration)", v->r[VR_G0] * 1e3, v->r[VR_MAX_PENETRATION] * 1e3);
        return NULL;
    }
    m = (model_runtime *)zalloc(1, sizeof *m);
    if (!m) {
        snprintf(msg, len, "out of memory");
        return NULL;
    }
    m->formulation = v->i[VR_FORMULATION];
    m->mode = v->i[VR_MODE];
    m->n = n;
    m->nb = nb;
    m->np = np = m->formulation == FORMULATION_3D ? 2 : 1;
    P = np;
    /* a geometry built in (an imported tip: its segments are the kernel's 'blades', its stations the liner's rows;
     * an FE casing's modes facing the built-in blades) */
    bg = np == 2 ? d->geo3d : d->geo2d;
    m->nk = bg ? bg->nb : nb;
    m->rows = bg && bg->n_rows > 0 ? bg->n_rows : np;
    m->g0 = v->r[VR_G0];
    m->k_r = v->r[VR_K_R];
    m->mu = v->r[VR_MU];
    /* the pythonfmu FMU hands theta to the library in degrees, which converts it back: same rounding */
    m->theta = (v->r[VR_THETA] * (180.0 / 3.14159265358979323846)) * (3.14159265358979323846 / 180.0);
    m->chord = v->r[VR_CHORD];
    m->dt_max = v->r[VR_DT_MAX];
    m->max_pen = v->r[VR_MAX_PENETRATION];
    m->v_slip = v->r[VR_SLIP_VELOCITY];

    /* contact geometry (the kernel's, from the ingredients baked at build time) */
    m->geo_mem = (double *)zalloc((size_t)nb * P * (3 * 3 + 2 * 3 * n) + 2 * (size_t)nb * P * n +
                                      2 * (size_t)nb * n + 2 * (size_t)n + (size_t)rr_work_size(n, m->nk, np) +
                                      (size_t)rr_cd_cache_size(n, m->nk, np),
                                  sizeof(double));
    if (!m->geo_mem) goto oom;
    g = m->geo_mem;
#define TAKE(ptr, count) (ptr = g + off, off += (count))
    TAKE(m->geo.points, (size_t)nb * P * 3);
    TAKE(m->geo.normals, (size_t)nb * P * 3);
    TAKE(m->geo.tangents, (size_t)nb * P * 3);
    TAKE(m->geo.Jb, (size_t)nb * P * 3 * n);
    TAKE(m->geo.Jc, (size_t)nb * P * 3 * n);
    TAKE(m->geo.G, (size_t)nb * P * n);
    TAKE(m->geo.A, (size_t)nb * n);
    TAKE(m->geo.B, (size_t)nb * n);
    TAKE(m->geo.S, (size_t)nb * P * n);
    TAKE(m->geo.T2, 2 * (size_t)n);
    TAKE(m->cwork, (size_t)rr_work_size(n, m->nk, np));
    TAKE(m->cache, (size_t)rr_cd_cache_size(n, m->nk, np));
#undef TAKE
    spec.n = n;
    spec.nb = nb;
    spec.np = np;
    spec.rotations = 1;
    spec.r_tip = d->r_tip;
    spec.stagger = d->stagger;
    spec.theta = np == 2 ? m->theta : 0.0;
    spec.chord = np == 2 ? m->chord : 0.0;
    spec.z_cg = d->z_cg;
    spec.blade_dof0 = d->blade_dof0;
    spec.n_ritz = d->n_ritz;
    spec.psi_tip = d->psi_tip;
    spec.casing_dof0 = d->casing_dof0;
    spec.n_modes = d->n_modes;
    spec.modes = d->modes;
    spec.T = d->T;
    spec.Rot = d->Rot;
    if (rr_contact_geometry(&spec, &m->geo) != 0) {
        snprintf(msg, len, "contact geometry: invalid (chord %g m)", m->chord);
        model_free(m);
        return NULL;
    }
    m->contact.n = n;
    m->contact.nb = nb;
    m->contact.np = np;
    m->contact.g0 = m->g0;
    m->contact.k_r = m->k_r;
    m->contact.mu = m->mu;
    m->contact.chord = np == 2 && m->chord > 1e-300 ? m->chord : 1e-300;
    m->contact.G = m->geo.G;
    m->contact.A = m->geo.A;
    m->contact.B = m->geo.B;
    m->contact.v_slip = m->v_slip;
    /* the normal law: the kernel's one dispatch (rr_laws.c), the same as the library's */
    m->contact.law.id = v->i[VR_LAW] == LAW_BILINEAR ? RR_LAW_BILINEAR : RR_LAW_PENALTY;
    if (m->contact.law.id == RR_LAW_BILINEAR) {
        m->contact.law.par[RR_BILINEAR_KNEE] = v->r[VR_KNEE];
        m->contact.law.par[RR_BILINEAR_RATIO] = v->r[VR_STIFFNESS_RATIO];
    }
    if (rr_law_check(&m->contact.law) != 0) {
        snprintf(msg, len, "the normal law's parameters are refused (knee %g m, stiffness_ratio %g)", v->r[VR_KNEE],
                 v->r[VR_STIFFNESS_RATIO]);
        model_free(m);
        return NULL;
    }
    m->contact.S = m->geo.S;
    m->contact.points = m->geo.points;
    m->contact.normals = m->geo.normals;
    m->contact.tangents = m->geo.tangents;
    m->contact.T2 = m->geo.T2;
    m->contact.work = m->cwork;
    if (bg) { /* the library's own arrays (built at the parameter file's cone angle and chord) */
        const model_geometry *tp = bg;
        m->contact.nb = tp->nb;
        m->contact.chord = tp->chord;
        m->contact.G = tp->G;
        m->contact.A = tp->A;
        m->contact.B = tp->B;
        m->contact.S = tp->S;
        m->contact.points = tp->points;
        m->contact.normals = tp->normals;
        m->contact.tangents = tp->tangents;
        m->contact.seg_len = tp->seg_len;
        m->contact.seg_k = tp->seg_k;
        m->contact.g_off = tp->g_off;
        m->contact.nloc = tp->nloc;
        m->contact.cols = tp->cols;
        m->contact.nb_out = tp->nb_out;
        m->contact.blade_of = tp->blade_of;
        m->contact.n_rows = tp->n_rows;
        m->contact.point_row = tp->point_row;
        m->contact.point_share = tp->point_share;
    }

    /* integrator state and step matrices */
    m->q = (double *)zalloc(2 * (size_t)n, sizeof(double));
    m->Ainv = (double *)zalloc(5 * nn + (size_t)n, sizeof(double));
    m->piv = (int *)zalloc((size_t)n, sizeof(int));
    /* quasi-static (and the step limit): q_static, K, F, static work, the 2n x 2n matrix, M^-1, eigenvalues */
    m->qs = (double *)zalloc((size_t)n + nn + (size_t)n + (size_t)rr_static_work_size(n) + 4 * nn + nn +
                                 3 * 2 * (size_t)n + nn,
                             sizeof(double));
    m->siwork = (int *)zalloc(2 * (size_t)n, sizeof(int));
    if (!m->q || !m->Ainv || !m->piv || !m->qs || !m->siwork) goto oom;
    if (d->blk_nb > 0) { /* the step by blocks: its store, scratch and pivots in one allocation */
        int big = d->blk_ns > d->blk_m ? d->blk_ns : d->blk_m;
        size_t store = (size_t)rr_cd_blocks_size(d->blk_ns, d->blk_nb, d->blk_m, d->blk_nc);
        size_t work = (size_t)rr_cd_blocks_work_size(d->blk_ns, d->blk_m, d->blk_nc);
        if (d->blk_nc > big) big = d->blk_nc;
        m->blk_store = (double *)zalloc(store + work + (size_t)big, sizeof(double));
        if (!m->blk_store) goto oom;
        m->blk_work = m->blk_store + store;
        m->blk_piv = (int *)(m->blk_work + work); /* big ints fit in big doubles */
    }
    m->qp = m->q + n;
    m->K2 = m->Ainv + nn;
    m->Cm1 = m->K2 + nn;
    m->mwork = m->Cm1 + nn; /* 2 nn */
    m->f = m->mwork + 2 * nn;
    m->Kw = m->qs + n;
    m->Fw = m->Kw + nn;
    m->swork = m->Fw + n;
    m->Aeig = m->swork + rr_static_work_size(n);
    m->Minv = m->Aeig + 4 * nn;
    m->wr = m->Minv + nn;
    m->wi = m->wr + 2 * n;
    m->ework = m->wi + 2 * n;
    m->Jv = m->ework + 2 * n;
    if (rr_inverse(n, d->M, m->Minv, m->Aeig, m->siwork) != 0) {
        snprintf(msg, len, "the mass matrix is singular");
        model_free(m);
        return NULL;
    }
    m->st.t = 0.0;
    m->st.dt = 0.0;
    m->st.phi = 0.0;
    m->st.max_pen = m->max_pen;
    m->st.steps = 0;
    m->st.diverged = 0;
    m->st.q = m->q;
    m->st.q_prev = m->qp;
    m->mats.n = n;
    m->mats.Ainv = m->Ainv;
    m->mats.K2 = m->K2;
    m->mats.Cm1 = m->Cm1;
    m->mats.f = m->f;
    m->job.state = &m->st;
    m->job.contact = &m->contact;
    m->job.mats = &m->mats;
    m->job.t_ramp = 0.0;
    m->job.rec_every = 1;
    m->job.rec_cap = 0;
    m->job.out_index = OUTPUT_INDEX;
    /* the contact evaluation of a step's last state is kept for the next step (the kernel checks it is that
     * state at those inputs): a communication step costs its substeps, not one evaluation more */
    m->job.cache = m->cache;
    m->job.cache_valid = 0;
    /* the casing's surface: the liner (worn or rigid) and the engine's closure and offset, read at every step */
    {
        int ns = v->i[VR_N_SECTORS];
        m->surf.n_sectors = ns;
        m->surf.wears = v->i[VR_LINER] == LINER_ABRADABLE;
        m->surf.yield_force = v->r[VR_YIELD_FORCE];
        m->surf.hardening = v->r[VR_HARDENING];
        m->surf.thickness = v->r[VR_LINER_THICKNESS];
        if (bg && bg->band > 0.0) { /* an imported tip: its own axial extent and footprint (Liner.for_model's) */
            m->cell_area = d->r_tip * (6.283185307179586476925286766559 / ns) * bg->band;
            m->surf.work_weight = m->cell_area / bg->tip_area;
        } else {
            m->cell_area = d->r_tip * (6.283185307179586476925286766559 / ns) * (m->chord * rr_cos(d->stagger));
            m->surf.work_weight = m->cell_area / (BLADE_THICKNESS * m->chord);
        }
        m->surf_mem = (double *)zalloc((size_t)rr_surface_table_size(m->nk, np, ns) + (size_t)m->rows * ns,
                                       sizeof(double));
        if (!m->surf_mem) goto oom;
        m->surf.tables = m->surf_mem;
        m->surf.depth = m->surf_mem + rr_surface_table_size(m->nk, np, ns);
        if (rr_surface_init(&m->contact, &m->surf) != 0) {
            snprintf(msg, len, "liner: the kernel refused its parameters (n_sectors %d, yield_force %g N, "
                     "liner_thickness %g m)", ns, m->surf.yield_force, m->surf.thickness);
            model_free(m);
            return NULL;
        }
        /* the surface is seen by the steps from the first one that needs it (transient_step) */
    }
    return m;
oom:
    snprintf(msg, len, "out of memory");
    model_free(m);
    return NULL;
}

double model_time_advanced(const model_runtime *m) { return m->advanced; }

static void set_clearance(model_runtime *m, double g0)
{
    m->g0 = g0;
    m->contact.g0 = g0;
}

static void finish_outputs(model_values *v, double max_real)
{
    v->i[VR_N_CONTACT] = (int)v->r[VR_N_CONTACT];
    v->r[VR_MAX_REAL_EIG] = max_real;
}

/* substeps of a step h at spin speed w: the step limit is evaluated once per whole rad/s */
static int substeps(model_runtime *m, double w, double h, char *msg, size_t len)
{
    double band = rr_ceil(w), cap;
    if (m->have_plan && m->plan_h == h && m->plan_band == band) return m->plan_n;
    if (!m->have_lim || m->lim_band != band) {
        double lim = critical_step(m, band);
        if (!(lim > 0.0)) {
            snprintf(msg, len, "the central-difference stability limit could not be computed at %g rad/s", band);
            return -1;
        }
        m->lim = lim;
        m->lim_band = band;
        m->have_lim = 1;
    }
    cap = m->dt_max < 0.5 * m->lim ? m->dt_max : 0.5 * m->lim;
    {
        double nd = rr_ceil(h / cap * (1.0 - 1e-9));
        if (!(nd <= MODEL_MAX_SUBSTEPS)) {
            char bh[32], bc[32], bt[32];
            snprintf(msg, len, "communication step h = %s s needs %.0f substeps of at most %s s (dt_max, or half the "
                     "central-difference limit at %g rad/s); at most %d are taken in one step (h <= %s s)",
                     core_num(h, bh, sizeof bh), nd, core_num(cap, bc, sizeof bc), band, MODEL_MAX_SUBSTEPS,
                     core_num(MODEL_MAX_SUBSTEPS * cap, bt, sizeof bt));
            return -1;
        }
        m->plan_n = nd < 1.0 ? 1 : (int)nd;
    }
    m->plan_h = h;
    m->plan_band = band;
    m->have_plan = 1;
    return m->plan_n;
}

/* the liner's summary and the clearance the engine keeps, into the outputs */
static void wear_outputs(model_runtime *m, model_values *v)
{
    const double *out = m->wear;
    int k;
    double closure = v->r[VR_CLEARANCE_CLOSURE];
    if (!m->have_wear || m->surf.changed) {
        rr_surface_summary(&m->contact, &m->surf, m->cell_area, m->wear);
        m->surf.changed = 0;
        m->have_wear = 1;
    }
    for (k = 0; k < RR_WEAR_OUT; ++k) {
        if (k == RR_WEAR_LOBES)
            v->i[WEAR_INDEX[k]] = (int)out[k];
        else
            v->r[WEAR_INDEX[k]] = out[k];
    }
    v->r[VR_CLEARANCE_EFFECTIVE] = m->g0 - closure + out[RR_WEAR_MEAN];
}

/* the engine's inputs into the casing's surface. A rigid liner with them at zero adds exactly 0 to every gap: the
 * kernel then runs without the surface (the paper's loop, none of its cost); attached again as soon as anything is
 * nonzero. Once worn, the liner stays attached (its depths are nonzero) */
static void attach_surface(model_runtime *m, const model_values *v)
{
    static const int amp_vr[] = {VR_CASING_LOBE2_AMPLITUDE, VR_CASING_LOBE3_AMPLITUDE, VR_CASING_LOBE4_AMPLITUDE};
    static const int phase_vr[] = {VR_CASING_LOBE2_PHASE, VR_CASING_LOBE3_PHASE, VR_CASING_LOBE4_PHASE};
    int k, lobes = 0;
    m->surf.closure = v->r[VR_CLEARANCE_CLOSURE];
    m->surf.offset_x = v->r[VR_CASING_OFFSET_X];
    m->surf.offset_y = v->r[VR_CASING_OFFSET_Y];
    for (k = 0; k < 3; ++k) { /* lobes 2, 3, 4: the casing out of round */
        m->surf.lobe_amp[k + 2] = v->r[amp_vr[k]];
        m->surf.lobe_phase[k + 2] = v->r[phase_vr[k]];
        if (m->surf.lobe_amp[k + 2] != 0.0) lobes = 1;
    }
    m->contact.surface = m->surf.wears || m->surf.closure != 0.0 || m->surf.offset_x != 0.0 ||
                                 m->surf.offset_y != 0.0 || lobes
                             ? &m->surf
                             : NULL;
}

static model_status transient_step(model_runtime *m, model_values *v, double w, double me, double h, int to_event,
                                   int *event, char *msg, size_t len)
{
    const model_data *d = &MODEL_DATA;
    int n = m->n, i, ns, done;
    double dt;
    size_t k, nn = (size_t)n * n;
    if (m->st.diverged) {
        snprintf(msg, len, "the run diverged in an earlier step");
        return MODEL_DISCARD;
    }
    ns = substeps(m, w, h, msg, len);
    if (ns < 1) return MODEL_ERROR;
    dt = h / ns;
    /* the matrices first: a step refused here leaves the state as it was (the two-step scheme untouched) */
    if (!m->have_mats || m->mats_omega != w || m->mats_dt != dt) {
        int bad;
        if (d->blk_nb > 0) { /* by blocks, as the library from BLOCK_MIN_DOFS dofs: a step linear in the blades */
            bad = rr_cd_build_blocks(n, d->blk_ns, d->blk_nb, d->blk_m, d->blk_nc, d->M, d->D, d->K, d->G1, d->C1,
                                     d->N2, d->S2, NULL, d->S4, w, 0.0, dt, m->blk_store, &m->blocks, m->blk_work,
                                     m->blk_piv);
            m->mats.blocks = &m->blocks;
        } else {
            bad = rr_cd_build(n, d->M, d->D, d->K, d->G1, d->C1, d->N2, d->S2, NULL, d->S4, w, 0.0, dt, m->Ainv, m->K2,
                              m->Cm1, m->mwork, m->piv);
            m->mats.blocks = NULL;
        }
        if (bad != 0) {
            m->have_mats = 0; /* the buffers hold a failed build */
            snprintf(msg, len, "the central-difference matrix is singular at %g rad/s, dt = %g s", w, dt);
            return MODEL_ERROR;
        }
        for (k = 0; k < (size_t)n; ++k) m->f[k] = 1.0 * w * w * d->f_unit[k];
        m->have_mats = 1;
        m->mats_omega = w;
        m->mats_dt = dt;
    }
    (void)nn;
    if (dt != m->st.dt) { /* restart the two-step scheme at the same velocity */
        for (i = 0; i < n; ++i) {
            double vel = (m->q[i] - m->qp[i]) / m->st.dt;
            if (m->st.dt == 0.0) vel = 0.0; /* at rest before the first step */
            m->qp[i] = m->q[i] - dt * vel;
        }
        m->st.dt = dt;
    }
    attach_surface(m, v);
    m->job.n_steps = ns;
    m->job.omega = w;
    m->job.me = me;
    m->job.n_rec = 0;
    m->job.out_dest = v->r;
    m->job.stop_on_contact = to_event;
    {
        double t0 = m->st.t;
        done = rr_cd_run(&m->job);
        m->advanced = m->st.t - t0;
    }
    finish_outputs(v, 0.0);
    wear_outputs(m, v);
    v->r[VR_DT_INTERNAL] = dt;
    v->i[VR_N_SUBSTEPS] = done;
    *event = done < ns && !m->st.diverged; /* only stop_on_contact ends a run early without a divergence */
    if (*event) return MODEL_OK;
    if (done < ns || m->st.diverged) {
        /* the time it reached is the wrapper's to say: the last successful time, the one a master reads */
        snprintf(msg, len, "the run diverged: a blade penetrated the casing deeper than max_penetration = %g mm (or "
                 "the state stopped being finite); the outputs are those of that state", m->max_pen * 1e3);
        return MODEL_DISCARD;
    }
    return MODEL_OK;
}

/* the balanced static solution at (w, me) and its stability; outputs at frame angle phi */
static model_status static_solution(model_runtime *m, model_values *v, double w, double me, double phi, char *msg,
                                  size_t len)
{
    const model_data *d = &MODEL_DATA;
    int n = m->n, i, j, k, its, ok;
    size_t nn = (size_t)n * n;
    double rel, gmin, max_real = -HUGE_VAL;
    double *q = m->Ainv; /* the transient buffers are free in this mode: the candidate solution */
    double *J = m->K2, *A = m->Aeig, *C = m->Cm1;
    rr_k_omega(m->n, d->K, d->S2, d->N2, d->C1, d->S4, w, m->Kw);
    for (i = 0; i < n; ++i) m->Fw[i] = me * w * w * d->f_unit[i];
    m->contact.g0 = m->g0 - v->r[VR_CLEARANCE_CLOSURE]; /* the engine's closure: uniform, so a balanced solution still is */
    ok = rr_static_solve(&m->contact, w, m->Kw, m->Fw, m->have_qs ? m->qs : NULL, 1e-10, 60, q, &rel, &its, m->swork,
                         m->siwork);
    if (!ok) {
        snprintf(msg, len, "no balanced static solution at Omega = %g rad/s, imbalance = %g kg.m, g0 = %g mm "
                 "(relative residual %.2e); the outputs hold the last solution", w, me, m->g0 * 1e3, rel);
        return MODEL_DISCARD;
    }
    /* x' = A x, x = (q, q'): A = [[0, I], [-M^-1 (K(W) - J), -M^-1 (D + W G1 - Jv)]] */
    rr_jacobian(&m->contact, q, NULL, w, J, m->Jv);
    for (k = 0; k < (int)nn; ++k) {
        m->Kw[k] = m->Kw[k] - J[k];
        C[k] = d->D[k] + w * d->G1[k];
        C[k] = C[k] - m->Jv[k];
    }
    for (i = 0; i < 2 * n; ++i)
        for (j = 0; j < 2 * n; ++j) A[(size_t)i * 2 * n + j] = 0.0;
    for (i = 0; i < n; ++i) {
        A[(size_t)i * 2 * n + n + i] = 1.0;
        for (j = 0; j < n; ++j) {
            double sk = 0.0, sc = 0.0;
            for (k = 0; k < n; ++k) {
                double mi = m->Minv[(size_t)i * n + k];
                sk += mi * m->Kw[(size_t)k * n + j];
                sc += mi * C[(size_t)k * n + j];
            }
            A[(size_t)(n + i) * 2 * n + j] = -sk;
            A[(size_t)(n + i) * 2 * n + n + j] = -sc;
        }
    }
    if (rr_eigenvalues(2 * n, A, m->wr, m->wi, m->ework) != 0) {
        snprintf(msg, len, "the eigenvalues of the linearised system did not converge at Omega = %g rad/s", w);
        return MODEL_DISCARD;
    }
    for (i = 0; i < 2 * n; ++i)
        if (m->wr[i] > max_real) max_real = m->wr[i];
    for (i = 0; i < n; ++i) m->qs[i] = q[i];
    m->have_qs = 1;
    rr_outputs(&m->contact, m->qs, NULL, w, phi, OUTPUT_INDEX, v->r);
    finish_outputs(v, max_real);
    wear_outputs(m, v);
    v->r[VR_DT_INTERNAL] = 0.0;
    v->i[VR_N_SUBSTEPS] = 0;
    /* the physical scale of a transient applies here too: a balanced solution that needs a deeper
     * penetration than max_penetration is no solution of this model (the blade cuts the case) */
    gmin = v->r[OUTPUT_INDEX[RR_OUT_BLADE_BLOCKS * m->nb + RR_OUT_GAP_MIN]];
    if (gmin < -m->max_pen) {
        v->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        snprintf(msg, len, "the balanced solution at Omega = %g rad/s, imbalance = %g kg.m, g0 = %g mm penetrates "
                 "the casing by %.4g mm, deeper than max_penetration = %g mm: a divergence (the outputs are that "
                 "solution's)", w, me, m->g0 * 1e3, -gmin * 1e3, m->max_pen * 1e3);
        return MODEL_DISCARD;
    }
    v->i[MODEL_INFO.vr_status] = max_real > RE_TOL ? STATUS_UNSTABLE : STATUS_OK;
    return MODEL_OK;
}

model_status model_check_set(const model_runtime *m, const model_values *v, int vr, double x, char *msg, size_t len)
{
    (void)v;
    if (vr == VR_G0 && x < -m->max_pen) {
        snprintf(msg, len, "g0 = %.6g mm: an interference deeper than max_penetration = %.6g mm is a divergence "
                 "(accepted: g0 >= -max_penetration)", x * 1e3, m->max_pen * 1e3);
        return MODEL_ERROR;
    }
    return MODEL_OK;
}

static model_status step(model_runtime *m, model_values *v, double h, int to_event, int *event, char *msg, size_t len)
{
    double w = v->r[VR_OMEGA], me = v->r[VR_IMBALANCE], g0 = v->r[VR_G0];
    model_status s;
    m->advanced = 0.0;
    *event = 0;
    if (g0 != m->g0) set_clearance(m, g0);
    if (m->mode == MODE_TRANSIENT) {
        s = transient_step(m, v, w, me, h, to_event, event, msg, len);
        if (s == MODEL_OK) v->i[MODEL_INFO.vr_status] = STATUS_OK;
        return s;
    }
    s = static_solution(m, v, w, me, m->phi_qs + w * h, msg, len);
    if (s == MODEL_OK) {
        m->phi_qs += w * h;
        m->advanced = h;
    }
    return s;
}

model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len)
{
    int event;
    (void)t; /* autonomous */
    return step(m, v, h, 0, &event, msg, len);
}

/* quasi_static: a balanced solution has no time inside the step, so no event either */
model_status model_step_to_event(model_runtime *m, model_values *v, double t, double h, int *event, char *msg,
                                 size_t len)
{
    (void)t;
    return step(m, v, h, m->mode == MODE_TRANSIENT, event, msg, len);
}

model_status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len)
{
    double g0 = v->r[VR_G0];
    (void)t;
    if (g0 != m->g0) set_clearance(m, g0);
    if (m->mode != MODE_QUASI_STATIC) {
        /* the outputs of the current state against the casing as the engine's inputs place it (the initial
         * outputs: a transient build reads no input after initialisation) */
        attach_surface(m, v);
        m->surf.phi = m->st.phi;
        rr_outputs(&m->contact, m->q, NULL, v->r[VR_OMEGA], m->st.phi, OUTPUT_INDEX, v->r);
        finish_outputs(v, 0.0);
        wear_outputs(m, v);
        return MODEL_OK;
    }
    if (!m->have_qs) {
        /* no solution found yet: the outputs of the rotor at rest against the casing (g0 less the engine's
         * closure), which 'status' and 'message' qualify when no balanced solution is found at these inputs */
        m->contact.g0 = m->g0 - v->r[VR_CLEARANCE_CLOSURE];
        rr_outputs(&m->contact, m->qs, NULL, v->r[VR_OMEGA], m->phi_qs, OUTPUT_INDEX, v->r);
        finish_outputs(v, 0.0);
        wear_outputs(m, v);
    }
    return static_solution(m, v, v->r[VR_OMEGA], v->r[VR_IMBALANCE], m->phi_qs, msg, len);
}

/* ------------------------------------------------------------------ state snapshots */
/* layout: tag, n, formulation, mode, g0, t, dt, phi, steps, diverged, have_qs, phi_qs, the liner's angle and
 * plastic work, its cells' count, q, qp, qs, the liner's depths (np x n_sectors), the engine's inputs the liner was
 * last cut at (NaN before the first cut: a rollback to then cuts at the next step's inputs first) */
#define STATE_HEAD 15
#define STATE_CUT ((int)(sizeof(((rr_surface *)0)->cut_inputs) / sizeof(double)))

static size_t liner_cells(const model_runtime *m) { return (size_t)m->rows * m->surf.n_sectors; }

size_t model_state_size(const model_runtime *m)
{
    return STATE_HEAD + 3 * (size_t)m->n + liner_cells(m) + STATE_CUT;
}

void model_state_save(const model_runtime *m, double *out)
{
    int n = m->n, i;
    size_t k;
    out[0] = STATE_TAG;
    out[1] = n;
    out[2] = m->formulation;
    out[3] = m->mode;
    out[4] = m->g0;
    out[5] = m->st.t;
    out[6] = m->st.dt;
    out[7] = m->st.phi;
    out[8] = (double)m->st.steps;
    out[9] = m->st.diverged;
    out[10] = m->have_qs;
    out[11] = m->phi_qs;
    out[12] = m->surf.phi;
    out[13] = m->surf.plastic_work;
    out[14] = (double)liner_cells(m);
    for (i = 0; i < n; ++i) {
        out[STATE_HEAD + i] = m->q[i];
        out[STATE_HEAD + n + i] = m->qp[i];
        out[STATE_HEAD + 2 * n + i] = m->qs[i];
    }
    for (k = 0; k < liner_cells(m); ++k) out[STATE_HEAD + 3 * (size_t)n + k] = m->surf.depth[k];
    for (i = 0; i < STATE_CUT; ++i) out[STATE_HEAD + 3 * (size_t)n + liner_cells(m) + i] = m->surf.cut_inputs[i];
}

int model_state_restore(model_runtime *m, const double *in, size_t count)
{
    int n = m->n, i;
    size_t k, cells = liner_cells(m);
    if (count != model_state_size(m) || in[0] != STATE_TAG || in[1] != n || in[2] != m->formulation ||
        in[3] != m->mode || !(in[6] >= 0.0) || !(in[8] >= 0.0) || (in[9] != 0.0 && in[9] != 1.0) ||
        (in[10] != 0.0 && in[10] != 1.0) || in[14] != (double)cells || !(in[13] >= 0.0))
        return -1;
    for (i = 4; i < (int)count - STATE_CUT; ++i)
        if (!isfinite(in[i])) return -1;
    for (i = (int)count - STATE_CUT; i < (int)count; ++i) /* never cut (NaN) or a finite input */
        if (isinf(in[i])) return -1;
    for (k = 0; k < cells; ++k)
        if (!(in[STATE_HEAD + 3 * (size_t)n + k] >= 0.0)) return -1; /* a worn depth is never negative */
    set_clearance(m, in[4]);
    m->st.t = in[5];
    m->st.dt = in[6];
    m->st.phi = in[7];
    m->st.steps = (long long)in[8];
    m->st.diverged = (int)in[9];
    m->have_qs = (int)in[10];
    m->phi_qs = in[11];
    for (i = 0; i < n; ++i) {
        m->q[i] = in[STATE_HEAD + i];
        m->qp[i] = in[STATE_HEAD + n + i];
        m->qs[i] = in[STATE_HEAD + 2 * n + i];
    }
    m->surf.phi = in[12];
    m->surf.plastic_work = in[13];
    m->have_wear = 0; /* another profile: its summary is computed anew */
    for (k = 0; k < cells; ++k) m->surf.depth[k] = in[STATE_HEAD + 3 * (size_t)n + k];
    for (i = 0; i < STATE_CUT; ++i) m->surf.cut_inputs[i] = in[STATE_HEAD + 3 * (size_t)n + cells + i];
    m->have_mats = 0; /* dt may differ */
    return 0;
}
