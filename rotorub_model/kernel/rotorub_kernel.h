/*
 * rotorub kernel: the hot path of the blade-tip / casing contact model in portable C99
 * (no libm on x86_64 and aarch64: the elementary functions are rr_math.h's). One source, used by the Python library (through ctypes), by the pythonfmu
 * FMU (a prebuilt copy in its resources) and by the native FMI 2.0 FMU.
 *
 * What it holds:
 *   - the contact laws: 2D point law and 3D chord law (eq. 5-8 of Parent, Thouverez &
 *     Chevillot 2014) with Coulomb friction along the sliding velocity of each contact point
 *     (regularised near zero), their projection on the generalised coordinates and the
 *     Jacobians (in q and in q') the static and stability solvers use;
 *   - the outputs of a state (per-blade forces, gaps, chord fraction; casing resultant,
 *     friction torque, fan-disk displacement, smallest gap, blades in contact);
 *   - the explicit central-difference substep loop on dense matrices.
 *
 * What it does not hold: the structure's matrices and the contact geometry (gap
 * gradients, projection rows), which the caller builds once and passes by pointer.
 * Matrices are dense, row-major, double precision. Nothing here allocates memory.
 *
 * Conventions (docs/THEORY.md): SI units; gaps positive when open; F_N >= 0 is the
 * magnitude of the normal force. Friction: at contact point p the blade slides over the casing
 * along e_t at v_p = omega rho_p + S_p q' (rho_p = (e_z x r_p).e_t, S_p = e_t.(J_b - J_c)); the
 * friction force on the blade is -mu tanh(v_p / v_slip) w_p e_t, w_p >= 0 the point's share of
 * the normal force. Spin and sliding are positive along +e_t (the spin direction).
 *
 * Floating-point: the arithmetic is written in a fixed order and must be compiled
 * without contraction to FMA or reassociation (-ffp-contract=off, no -ffast-math), so
 * that every platform and both FMUs give the same numbers as the library.
 */
#ifndef ROTORUB_KERNEL_H
#define ROTORUB_KERNEL_H

#ifdef __cplusplus
extern "C" {
#endif

/* Exported from the kernel's own shared library; an FMU that compiles the kernel in defines
 * RR_API empty so that only its fmi2 functions are visible. */
#ifndef RR_API
#  if defined(_WIN32)
#    if defined(RR_BUILD_SHARED)
#      define RR_API __declspec(dllexport)
#    else
#      define RR_API
#    endif
#  elif defined(__GNUC__)
#    define RR_API __attribute__((visibility("default")))
#  else
#    define RR_API
#  endif
#endif

/* Bumped whenever a struct layout or a signature below changes. */
#define RR_ABI_VERSION 9

/* Per-blade law values (rr_laws): F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, chord fraction, potential. */
#define RR_LAW_WIDTH 8

/* ------------------------------------------------------------------ contact laws
 * The normal law of a blade tip, as named data with one dispatch (rr_laws.c): a law id and its parameters.
 * The law gives the pressure p(delta) of a penetration delta = -gap >= 0 per unit chord, k_r / l_c times
 * a shape (3D), or the tip force k_r times the shape (2D): a chord pressed uniformly carries k_r times the
 * shape in both formulations. Everything derived from the law (forces, moments and their derivatives, the
 * potential for the energy checks, the largest slope for the explicit scheme's step, the liner's return
 * map) is computed here, for the library and both FMUs.
 *   RR_LAW_PENALTY   shape delta                                  (the paper's penalty law)
 *   RR_LAW_BILINEAR  shape delta + (ratio - 1) (delta - knee)_+    (a coating then a stiffer, ratio > 1, or
 *                    softer, ratio < 1, layer beyond the knee penetration; par: knee [m] > 0, ratio > 0) */
enum { RR_LAW_PENALTY = 0, RR_LAW_BILINEAR = 1, RR_N_LAWS };
enum { RR_BILINEAR_KNEE = 0, RR_BILINEAR_RATIO = 1 };
#define RR_LAW_PARAMS 4
typedef struct {
    int id;                      /* RR_LAW_* */
    double par[RR_LAW_PARAMS];   /* the law's parameters, in its enum's order (unused ones 0) */
} rr_law;

/* Layout of the outputs of a state (rr_outputs): six per-blade blocks, then globals. */
enum {
    RR_OUT_FN = 0,       /* normal force per blade [N] */
    RR_OUT_FT = 1,       /* friction force per blade, opposing the spin when positive [N] */
    RR_OUT_GAP_LE = 2,   /* gap at the leading edge (2D: the tip gap) [m] */
    RR_OUT_GAP_TE = 3,   /* gap at the trailing edge (2D: the tip gap) [m] */
    RR_OUT_GAP_TIP = 4,  /* smallest gap of the blade [m] */
    RR_OUT_FRACTION = 5, /* chord fraction in contact (2D: 0 or 1) */
    RR_OUT_BLADE_BLOCKS = 6
};
enum {
    RR_OUT_CASING_X = 0, RR_OUT_CASING_Y, RR_OUT_CASING_Z, /* resultant on the casing [N] */
    RR_OUT_TORQUE,                                          /* axial torque on the rotor [N m] */
    RR_OUT_DISK_X, RR_OUT_DISK_Y,                           /* fan-disk centre [m] */
    RR_OUT_GAP_MIN,                                         /* smallest gap [m] */
    RR_OUT_N_CONTACT,                                       /* blades with F_N > 0 */
    RR_OUT_GLOBALS
};
/* The kernel's elementary functions (rr_math.h), for tests: out[i] = f(x[i]) (atan2: f(x[i], y[i]), y-first
 * as C's atan2(y, x) takes them: x holds the first argument). */
enum { RR_FN_SIN, RR_FN_COS, RR_FN_TAN, RR_FN_ATAN2, RR_FN_TANH, RR_FN_EXP, RR_FN_SQRT, RR_FN_FLOOR, RR_FN_CEIL };
RR_API void rr_elementary(int fn, int m, const double *x, const double *y, double *out);

/* number of outputs of a state for nb reported blades (rr_contact.nb_out, or nb) */
#define RR_N_OUT(nb) (RR_OUT_BLADE_BLOCKS * (nb) + RR_OUT_GLOBALS)

/* The casing's inner surface as the engine and a rub leave it (docs/THEORY.md, "Abradable liner"): an
 * abradable liner in n_sectors cells over the circumference (fixed frame), one row per contact point of a
 * blade (2D: the tip; 3D: LE and TE, the worn surface linear between them along the chord), each cell with
 * a worn depth; and two inputs from the engine, a uniform closure of the clearance and a rigid offset of
 * the casing's centre. A contact point's gap is its gap to the unworn, centred casing plus
 *     depth(row, sector of the point) - closure + n_r (offset_x cos th + offset_y sin th),
 * th the point's fixed-frame angle, n_r the radial part of the casing normal there. The liner's law, at
 * each cell a contact point sweeps in a step: elastic (the contact's penalty k_r) up to the yield force
 * F_y + H depth, material removed beyond it (depth grows so that the force returns to that bound; H the
 * linear hardening), never deeper than the liner's thickness; in 3D each end point carries half the chord
 * (k_r / 2, F_y / 2, H / 2: a chord pressed uniformly yields at the same total force as a 2D tip). The
 * surface is read by every function below that evaluates gaps, at the frame angle phi; only the time loop
 * (rr_cd_run) cuts it. Arrays are owned by the caller; rr_surface_init fills the tables. */
#define RR_WEAR_HARMONICS 8 /* profile harmonics in the summary */
#define RR_MAX_LOBES 8      /* casing distortion: lobe counts 2..RR_MAX_LOBES (1 is the offset) */
typedef struct {
    int n_sectors;       /* cells over 2 pi (>= 8) */
    int wears;           /* 1: cut by the law; 0: a fixed surface (the liner as it is, closure, offset) */
    double yield_force;  /* F_y [N] per blade tip (> 0) */
    double hardening;    /* H [N/m] (>= 0) */
    double thickness;    /* liner thickness [m]: no wear beyond (> 0) */
    double closure;      /* uniform closure of the clearance [m] (engine input; > 0 closes) */
    double offset_x;     /* rigid offset of the casing centre, fixed frame [m] (engine input) */
    double offset_y;
    /* the casing out of round (engine input): its inner radius grows by sum_n a_n cos(n (th - psi_n)), n = 2..
     * RR_MAX_LOBES, th the fixed-frame angle (psi_n: where a lobe is widest); a point's gap grows by n_r times
     * that. Entries 0 and 1 unused (lobe 1 is the offset). */
    double lobe_amp[RR_MAX_LOBES + 1];   /* a_n [m] */
    double lobe_phase[RR_MAX_LOBES + 1]; /* psi_n [rad] */
    double phi;          /* frame angle of the state the gaps are evaluated at; the time loop keeps it [rad] */
    double work_weight;  /* a cell's area over a blade tip's (the law is a tip's): the plastic work per cell is
                          * the law's times this, so that it is the yield pressure times the volume, whatever
                          * the cells' count (> 0) */
    double plastic_work; /* work dissipated in removing the liner since the start [J] (state) */
    int changed;         /* set when a cell is cut (a summary clears nothing: for the caller) */
    double *tables;      /* rr_surface_table_size(nb, np, n_sectors) doubles, filled by rr_surface_init */
    double *depth;       /* (np, n_sectors) worn depth [m] (state) */
    /* the inputs (closure, offset, lobes) the time loop last cut at; rr_surface_init clears them (NaN) so that
     * the first run cuts at its inputs before its first force (kernel-managed) */
    double cut_inputs[3 + 2 * (RR_MAX_LOBES + 1)];
} rr_surface;

/* Contact geometry and law parameters of one formulation (all arrays owned by the caller). */
typedef struct {
    int n;            /* generalised coordinates */
    int nb;           /* blades */
    int np;           /* contact points per blade: 1 (2D tip) or 2 (3D leading, trailing edge) */
    double g0;        /* nominal clearance [m] */
    double k_r;       /* normal stiffness of a whole blade tip [N/m] */
    double mu;        /* Coulomb friction coefficient */
    double chord;     /* chord length l_c [m] (any positive value for np = 1) */
    double v_slip;    /* velocity scale of the friction regularisation tanh(v / v_slip) [m/s] (> 0) */
    rr_law law;       /* the normal law (RR_LAW_PENALTY: the paper's) */
    /* Imported blades (docs/THEORY.md 9): a tip is a chain of chord stations, and each 'blade' of this struct is
     * a segment between two consecutive stations (np = 2: its leading and trailing end), with the chord law of
     * its own length over it; NULL / 0 for the built-in blades (one chord per blade, dense rows): */
    const double *seg_len;  /* (nb) each segment's chord length [m] (NULL: chord) */
    const double *seg_k;    /* (nb) each segment's share of k_r and of the liner's yield force (NULL: 1) */
    const double *g_off;    /* (nb*np) each point's rest gap beyond g0 [m] (NULL: 0) */
    int nloc;               /* > 0: every row below is stored compact, nloc columns, */
    const int *cols;        /* (nb, nloc) the dofs of segment j's rows (NULL: dense rows of n columns) */
    int nb_out;             /* blades the outputs report (0: nb) */
    const int *blade_of;    /* (nb) each segment's reported blade, ascending, its segments leading edge first */
    int n_rows;             /* rows of the casing surface's worn depth (0: np) */
    const int *point_row;   /* (nb*np) each point's row of the surface (NULL: its index within its blade) */
    const double *point_share; /* (nb*np) each point's share of a tip for the liner's law (its stations' tributary
                                * chord; 0 for a station's second point, which is its twin's; NULL: 1/np) */
    const double *G;  /* (nb*np, n) gap gradients: gap = g0 + G q */
    const double *A;  /* (nb, n) d eta / dq   (mean gap along the chord) */
    const double *B;  /* (nb, n) d zeta / dq  (gap slope along the chord) */
    const double *S;  /* (nb*np, n) sliding rows: relative sliding along e_t at each point = S q */
    const double *points;   /* (nb*np, 3) rest positions of the contact points (rotating frame) */
    const double *normals;  /* (nb*np, 3) outward casing normals */
    const double *tangents; /* (nb*np, 3) sliding directions e_t */
    const double *T2;    /* (2, n) fan-disk translation (rotating frame) */
    double *work;        /* scratch of at least rr_work_size(n, nb, np) doubles */
    rr_surface *surface; /* the casing's worn, closed and offset surface, or NULL (the paper's rigid casing) */
} rr_contact;

/* What the contact geometry is built from: the structure's maps at the fan disk and at the
 * casing, and the formulation's parameters (rr_contact_geometry). */
typedef struct {
    int n;                 /* generalised coordinates */
    int nb;                /* blades, at angles 2 pi j / nb */
    int np;                /* 1: 2D point tip; 2: 3D leading and trailing edges */
    int rotations;         /* 3D: disk/casing rotations and blade flexure enter the gap (0: 'geometry only') */
    double r_tip;          /* blade-tip radius [m] */
    double stagger;        /* blade stagger from the axis [rad] */
    double theta;          /* cone angle of the casing inner surface [rad] (3D) */
    double chord;          /* blade-tip chord [m] (3D) */
    double z_cg;           /* axial offset of the casing centre of gravity from the tip plane [m] */
    int blade_dof0;        /* first blade dof; blade j owns n_ritz dofs from blade_dof0 + j n_ritz */
    int n_ritz;            /* Ritz functions per blade */
    const double *psi_tip; /* (n_ritz) their values at the tip */
    int casing_dof0;       /* first casing dof: translation x, y, tilt x, y, then (cos, sin) per ring mode */
    int n_modes;           /* ring modes */
    const int *modes;      /* (n_modes) their nodal diameters */
    const double *T;       /* (3, n) fan-disk translation */
    const double *Rot;     /* (3, n) fan-disk rotation vector */
} rr_geometry_spec;

/* The contact geometry (all caller-allocated, P = np points per blade). */
typedef struct {
    double *points;   /* (nb, P, 3) rest positions, rotating frame, z from the tip plane */
    double *normals;  /* (nb, P, 3) outward normal of the casing surface */
    double *tangents; /* (nb, P, 3) sliding direction e_t */
    double *Jb;       /* (nb, P, 3, n) displacement of the blade point */
    double *Jc;       /* (nb, P, 3, n) displacement of the casing point facing it */
    double *G;        /* (nb*P, n) gap gradients */
    double *A, *B;    /* (nb, n) d eta, d zeta / dq */
    double *S;        /* (nb*P, n) sliding rows e_t.(J_b - J_c) */
    double *T2;       /* (2, n) fan-disk translation */
} rr_geometry;

/* The step's matrices by blocks, for a model whose dofs are a hub (the shaft: ns), nb blades of m dofs each that
 * couple to the hub only, and a casing (nc) that couples to nothing but through contact: n = ns + nb m + nc. Then
 * 2M/dt^2 - K and M/dt^2 - C/2dt are arrows (hub-hub, hub-blade, blade-hub, blade-blade blocks, the casing's) and
 * (M/dt^2 + C/2dt) q = r is solved by the Schur complement on the hub: a step costs nb (m^2 + 3 m ns) + ns^2 +
 * nc^2, linear in the blades, where the dense step costs n^2 (imported blades, docs/THEORY.md 9). */
typedef struct {
    int ns, nb, m, nc;
    const double *K2_hh, *K2_hb, *K2_bh, *K2_bb, *K2_cc; /* 2M/dt^2 - K: (ns,ns), (nb,ns,m), (nb,m,ns), (nb,m,m), (nc,nc) */
    const double *C_hh, *C_hb, *C_bh, *C_bb, *C_cc;      /* M/dt^2 - C/2dt, the same blocks */
    const double *A_hb;  /* (nb, ns, m) the hub-blade blocks of A = M/dt^2 + C/2dt */
    const double *Binv;  /* (nb, m, m) A_bb_j^-1 */
    const double *W;     /* (nb, m, ns) A_bb_j^-1 A_bh_j */
    const double *Sinv;  /* (ns, ns) (A_hh - sum_j A_hb_j A_bb_j^-1 A_bh_j)^-1 */
    const double *Cinv;  /* (nc, nc) A_cc^-1 */
} rr_cd_blocks;

/* Central-difference matrices at one (Omega, dt): (M/dt^2 + C/2dt)^-1, 2M/dt^2 - K, M/dt^2 - C/2dt. */
typedef struct {
    int n;
    const double *Ainv;  /* (n, n) */
    const double *K2;    /* (n, n) */
    const double *Cm1;   /* (n, n) */
    const double *f;     /* (n) imbalance force per unit m e [N / (kg m)] */
    const double *f0;    /* (n) load independent of the imbalance (blade inertia under dOmega/dt) [N], or NULL */
    const rr_cd_blocks *blocks; /* the same matrices by blocks (then Ainv, K2, Cm1 are not read), or NULL */
} rr_cd_matrices;

/* State of the two-step scheme. q and q_prev are owned by the caller. */
typedef struct {
    double t;          /* time of q [s] */
    double dt;         /* step [s] */
    double phi;        /* angle of the rotating frame [rad] */
    double max_pen;    /* divergence: a gap below -max_pen [m] */
    long long steps;   /* steps taken since the start */
    int diverged;      /* set when a gap fell below -max_pen or a value stopped being finite */
    double *q;         /* (n) displacements at t */
    double *q_prev;    /* (n) displacements at t - dt */
} rr_cd_state;

RR_API int rr_abi_version(void);
RR_API const char *rr_source_id(void);
/* doubles of scratch an rr_contact needs in its work pointer */
RR_API int rr_work_size(int n, int nb, int np);

/* Build the contact geometry of eq. (1) (2D) or eq. (3)-(4) linearised (3D; see docs/THEORY.md 4).
 * Returns 0, or -1 if the spec is invalid (np not 1 or 2, chord <= 0 in 3D). */
RR_API int rr_contact_geometry(const rr_geometry_spec *spec, rr_geometry *out);
/* The law of one blade from its gaps: np = 2 chord law (g_le, g_te), np = 1 point law (g_le); out: RR_LAW_WIDTH
 * values. */
RR_API void rr_blade_law(const rr_law *law, int np, double g_le, double g_te, double k, double l, double *out);
/* 0 if the law's id and parameters are valid, else -1. */
RR_API int rr_law_check(const rr_law *law);
/* The law's largest slope over its penetrations, per unit k_r (penalty: 1; bilinear: max(1, ratio)): what the
 * explicit scheme's stability limit must assume with every contact closed. */
RR_API double rr_law_max_slope(const rr_law *law);
/* The contact potential (the law's strain energy, summed over the blades) of m states given by their gaps
 * (m x nb*np, e.g. rr_gaps_batch's, or a run's gaps to a worn surface) [J]: its gradient is -F_nl without
 * friction. */
RR_API void rr_potential_batch(const rr_contact *c, int m, const double *gaps, double *out);
/* -dF_nl/dq with every blade in full contact at the law's largest slope (no surface): the stiffness the
 * explicit scheme's step and the static solver's starts assume (n x n, friction's part at spin omega). */
RR_API void rr_closed_stiffness(const rr_contact *c, double omega, double *Kc);
/* Gaps (nb*np) and per-blade law values (nb x RR_LAW_WIDTH) at q. */
RR_API void rr_laws(const rr_contact *c, const double *q, double *gaps, double *law);
/* Friction factors mu tanh(v_p / v_slip) of the nb*np points at (q, q', omega) (0 where the blade
 * does not touch); qdot NULL: at rest in the rotating frame (a static state). */
RR_API void rr_friction(const rr_contact *c, const double *q, const double *qdot, double omega, double *fr);
/* Generalised contact force F_nl(q, q'; omega) (n); qdot NULL: q' = 0. */
RR_API void rr_force(const rr_contact *c, const double *q, const double *qdot, double omega, double *f);
/* Jacobians dF_nl/dq (J) and dF_nl/dq' (Jv, or NULL), n x n row-major; J is not symmetric
 * when friction acts, Jv is the (negative semi-definite) damping of the regularised friction. */
RR_API void rr_jacobian(const rr_contact *c, const double *q, const double *qdot, double omega, double *J,
                        double *Jv);
/* Gaps of m states Q (m x n) into gaps (m x nb*np). */
RR_API void rr_gaps_batch(const rr_contact *c, int m, const double *Q, double *gaps);

/* The RR_N_OUT(nb) outputs of state (q, q') at spin omega, casing force and disk displacement
 * rotated by phi (phi = 0: rotating frame). If index is NULL they are written to dest[0..], else
 * dest[index[k]] = output k (straight into an FMU's value buffer). qdot NULL: q' = 0. */
RR_API void rr_outputs(const rr_contact *c, const double *q, const double *qdot, double omega, double phi,
                       const int *index, double *dest);
/* Outputs of m states Q (m x n) with velocities Qdot (m x n, or NULL) at spin omega, rotating
 * frame, into out (m x RR_N_OUT(nb)). */
RR_API void rr_outputs_batch(const rr_contact *c, int m, const double *Q, const double *Qdot, double omega,
                             double *out);

/* One call of the time loop: what to advance, with what, and where to put the results. A caller
 * that steps often (an FMU) keeps one job and only changes n_steps, omega and me between calls. */
typedef struct {
    rr_cd_state *state;
    const rr_contact *contact;
    const rr_cd_matrices *mats;
    int n_steps;          /* steps to take */
    double omega;         /* spin speed [rad/s]: advances the frame angle */
    double me;            /* imbalance m e [kg m] */
    double t_ramp;        /* imbalance ramp r(t) = min(t / t_ramp, 1); <= 0: r = 1 */
    int rec_every;        /* record every rec_every-th step of the run (counted by state->steps); < 0: the call's
                           * last step only (a master's communication point, whatever the steps before) */
    int rec_cap;          /* rows of rec_q / rec_out (0: no records) */
    int n_rec;            /* in: first free row; out: rows written */
    double *rec_q;        /* (rec_cap, n) the recorded q */
    double *rec_out;      /* (rec_cap, RR_N_OUT(nb)) their outputs, rotating frame (NULL: none) */
    const int *out_index; /* outputs of the final state (fixed frame) go to out_dest[out_index[k]] */
    double *out_dest;     /* (NULL: not written) */
    int done;             /* out: steps done (fewer than n_steps if the run diverged) */
    /* the liner's profile (rows' mean per cell) every rec_wear_every-th step of the run (counted by
     * state->steps), into rec_wear (rec_wear_cap rows of n_sectors) from row n_rec_wear (in/out) */
    int rec_wear_every, rec_wear_cap, n_rec_wear;
    double *rec_wear;
    /* 1: end the run after the first step that brings a gap below 0 from a state with none (a first contact:
     * an FMI 3.0 event), done < n_steps then and state->diverged unset; 0: run every step. The steps taken are
     * those of a run of done steps, bit for bit. */
    int stop_on_contact;
    /* NULL, or rr_cd_cache_size(n, nb, np) doubles: the contact evaluation of the final state is kept there with
     * what it depends on, and the next call starts from it instead of evaluating it again when that state and
     * those inputs are the same (a co-simulation step then costs what its substeps cost). The caller sets
     * cache_valid = 0 when it points the job at another contact; the kernel manages it otherwise. A surface that
     * wears is never cached. */
    double *cache;
    int cache_valid;
} rr_cd_job;
/* doubles of an rr_cd_job's cache */
RR_API int rr_cd_cache_size(int n, int nb, int np);

/* Advance job->n_steps central-difference steps at constant matrices, external force
 * f * me * r(t) + f0; the friction of each step uses the velocity (q - q_prev) / dt. Returns the steps done; fewer than n_steps if a gap fell below -max_pen or a
 * value stopped being finite (state->diverged is then set and further calls do nothing). */
RR_API int rr_cd_run(rr_cd_job *job);

/* ------------------------------------------------------------------ abradable liner */
/* Doubles of rr_surface.tables for nb blades of np points and n_sectors cells. */
RR_API int rr_surface_table_size(int nb, int np, int n_sectors);
/* Check the surface's parameters against the contact (np rows) and fill its tables (the points' angles
 * and normals, the profile's Fourier basis). Returns 0, or -1 if a parameter is out of range. */
RR_API int rr_surface_init(const rr_contact *c, rr_surface *s);
/* The liner's law at one cell: a point of raw gap g (its gap to the unworn surface, closure and offset
 * included) over a cell worn to *depth; the point's share of the normal law (law, stiffness k), yield force fy,
 * hardening h, thickness. Elastic (the law) while its force stays below fy + h depth, else the cell is cut so
 * that the force returns to that bound (a return map, exact for every law here: they are piecewise linear).
 * Cuts *depth (if wears) and adds the dissipated work to *work; returns the point's normal force after the cut. */
RR_API double rr_liner_law(const rr_law *law, double g, double k, double fy, double h, double thickness, int wears,
                           double *depth, double *work);
/* Summary of the worn profile (the rows' mean at every cell) into out[RR_WEAR_OUT]: largest and mean
 * depth [m], removed volume [m^3] (area_per_sector: a cell's area on the casing, m^2), the plastic work
 * [J], the dominant lobe count and the amplitudes of harmonics 1..RR_WEAR_HARMONICS [m]. The lobe rule: a profile
 * whose every harmonic is below RR_LOBE_UNIFORM times the mean depth is worn evenly (0 lobes); otherwise the largest
 * harmonic h is the lobe count when its amplitude is at least RR_LOBE_DOMINANCE times that of every harmonic that
 * is not a multiple of h (an h-lobed profile that is not a pure sinusoid has harmonics 2h, 3h, ... too), else 0
 * (no lobe dominates). 0 also when nothing is worn. */
#define RR_LOBE_DOMINANCE 2.0
#define RR_LOBE_UNIFORM 0.05
enum { RR_WEAR_MAX = 0, RR_WEAR_MEAN, RR_WEAR_VOLUME, RR_WEAR_WORK, RR_WEAR_LOBES, RR_WEAR_AMP,
       RR_WEAR_OUT = RR_WEAR_AMP + RR_WEAR_HARMONICS };
RR_API void rr_surface_summary(const rr_contact *c, const rr_surface *s, double area_per_sector, double *out);

/* ------------------------------------------------------------------ dense linear algebra */
/* LU with partial pivoting, in place (n x n row-major); returns 0, or -1 if a pivot is zero. */
RR_API int rr_lu(int n, double *A, int *piv);
/* Solve LU x = b in place after rr_lu. */
RR_API void rr_lu_solve(int n, const double *LU, const int *piv, double *b);
/* Ainv = A^-1 (A untouched); work: n*n doubles, piv: n ints. Returns 0 or -1 (singular). */
RR_API int rr_inverse(int n, const double *A, double *Ainv, double *work, int *piv);
/* Eigenvalues wr + i wi of A (n x n, destroyed): balancing, Householder reduction to Hessenberg
 * form, Francis double-shift QR (no eigenvectors); work: n doubles. Returns 0, or -1 if the QR
 * iteration did not converge. */
RR_API int rr_eigenvalues(int n, double *A, double *wr, double *wi, double *work);

/* ------------------------------------------------------------------ balanced static solutions */
/* Doubles and ints of scratch rr_static_solve needs. */
RR_API int rr_static_work_size(int n);
/* Balanced static solution of K q = F_nl(q) + F (eq. 10) at spin omega (q' = 0: the points slide at
 * omega rho_p), K the stiffness K(Omega): Newton with
 * the analytic contact Jacobian, LU, and a backtracking line search on |R|, tried from a list of
 * starts until one converges (|R| <= tol |F|): q0 (if not NULL), the linear response, the
 * responses with every contact closed at full, half and a tenth of its stiffness, the linear
 * response scaled by 0.5, 0.25, 1.5, 2; then a continuation in the imbalance from 0 in ten steps.
 * If none converges, q is the start with the smallest residual. Returns 1 (converged) or 0;
 * *residual = |R| / |F|, *iterations = Newton iterations in all. work: rr_static_work_size(n)
 * doubles, iwork: n ints. The contact's work buffer is used too. */
RR_API int rr_static_solve(const rr_contact *c, double omega, const double *K, const double *F, const double *q0,
                           double tol, int max_iter, double *q, double *residual, int *iterations, double *work,
                           int *iwork);

/* Newton from q alone (in/out; no other start, no continuation): the step of a continuation, which
 * must stay on the branch it follows. Returns 1 (converged) or 0; work and iwork as rr_static_solve. */
RR_API int rr_static_newton(const rr_contact *c, double omega, const double *K, const double *F, double tol,
                            int max_iter, double *q, double *residual, int *iterations, double *work, int *iwork);

/* K(Omega) = K0 + omega^2 (S2 + N2) + omega C1 (+ omega^4 S4, an imported blade's; S4 NULL for the built-in) (n x n),
 * in that order of operations (the library's matrices,
 * the FMUs' and the time loop's are the same bits). */
RR_API void rr_k_omega(int n, const double *K0, const double *S2, const double *N2, const double *C1, const double *S4,
                       double omega, double *out);
/* The explicit central-difference stability limit 2 / omega_max at spin omega: omega_max^2 the largest |eigenvalue|
 * of Minv (Kw + Kc), Kw = K(omega), Kc = rr_closed_stiffness (every blade closed at the law's largest slope).
 * work: 2 n*n + 3 n doubles. Returns the limit [s], or -1 if the eigenvalue iteration failed. */
RR_API double rr_critical_step(const rr_contact *c, double omega, const double *Minv, const double *Kw, double *work);
RR_API int rr_critical_step_work_size(int n);

/* The central-difference matrices at spin speed omega, angular acceleration omega_dot and step dt,
 * assembled in the library's order of operations: C = D + omega G1,
 * K = K0 + omega^2 (S2 + N2) + omega C1 + omega_dot E1 (+ omega^4 S4; E1, S4 may be NULL),
 * Ainv = (M/dt^2 + C/2dt)^-1, K2 = 2M/dt^2 - K, Cm1 = M/dt^2 - C/2dt.
 * work: 2 n*n doubles, piv: n ints. Returns 0 or -1 (singular). */
RR_API int rr_cd_build(int n, const double *M, const double *D, const double *K0, const double *G1,
                       const double *C1, const double *N2, const double *S2, const double *E1, const double *S4,
                       double omega, double omega_dot, double dt, double *Ainv, double *K2, double *Cm1, double *work,
                       int *piv);

/* The step's matrices by blocks (rr_cd_blocks) from the dense model matrices (read at the arrow's blocks only),
 * in rr_cd_build's arithmetic: store holds rr_cd_blocks_size(ns, nb, m, nc) doubles the struct's pointers are set
 * into; work rr_cd_blocks_work_size(ns, m, nc) doubles, piv max(ns, m, nc) ints. Returns 0, or -1 (a layout that
 * does not add up, or a singular block). */
RR_API int rr_cd_blocks_size(int ns, int nb, int m, int nc);
RR_API int rr_cd_blocks_work_size(int ns, int m, int nc);
RR_API int rr_cd_build_blocks(int n, int ns, int nb, int m, int nc, const double *M, const double *D, const double *K0,
                              const double *G1, const double *C1, const double *N2, const double *S2,
                              const double *E1, const double *S4, double omega, double omega_dot, double dt,
                              double *store, rr_cd_blocks *b, double *work, int *piv);

#ifdef __cplusplus
}
#endif
#endif
