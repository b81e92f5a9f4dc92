/*
 * engine_host.c - a fixed-step co-simulation master for a system of FMI 2.0 co-simulation FMUs, in C: no
 * Python in the process. It is what runs the engine system's SSP package (LP spool + blade-tip contact)
 * "as written" in a native process: fmu_src/systems/ssp.py reads the package (components, parameter sets,
 * connections, step) and calls this host with the value references; the simulation itself is C only.
 *
 *   cc -std=c99 -O2 -o engine_host engine_host.c -ldl
 *
 *   engine_host -n STEPS -s STEP [-t START] [-q]
 *               -F NAME=DIR:MODEL ...              an instance of the FMU unzipped in DIR (modelIdentifier MODEL)
 *               [-p NAME:VR=REAL]... [-I NAME:VR=INT]...   values set before initialisation
 *               [-c FROM:VR=TO:VR]...               a connection: Real output of FROM to Real input of TO
 *               [-o NAME:VR]... [-i NAME:VR]...     Real / Integer columns of the CSV
 *
 * Exchange (Jacobi, as fmu_src/systems/coupling.py's fmpy master and libcosim's fixed-step algorithm): at each
 * communication point t_k every input is set from the outputs of every FMU at t_k, then every FMU steps over
 * [t_k, t_k + h] with its inputs held. Output (stdout): a header "time,NAME:rVR...,NAME:iVR..." and one row
 * at t_0 (after the first exchange) and after every step, reals in %.17g.
 *
 * A step refused with fmi2Discard ends the run (fmi2Terminated asked or not: a fixed-step master cannot
 * retry), the rows so far are kept, every instance is terminated and freed: exit status 3 (4 after
 * fmi2Fatal); 1: an FMU could not be loaded, instantiated or initialised; 2: bad command line.
 */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L
#endif
#include <math.h>

#include "fmi2_host.h"

#define MAX_FMUS 8
#define MAX_ITEMS 256

typedef struct {
    const char *name, *dir, *model;
    fmi2_lib lib;
    fmi2Component c;
    char *guid;
} Fmu;

typedef struct { int fmu; fmi2ValueReference vr; double value; } RealSet;
typedef struct { int fmu; fmi2ValueReference vr; fmi2Integer value; } IntSet;
typedef struct { int from; fmi2ValueReference from_vr; int to; fmi2ValueReference to_vr; double value; } Link;
typedef struct { int fmu; fmi2ValueReference vr; } Column;

static Fmu fmus[MAX_FMUS];
static int n_fmus;

/* Jacobi exchange: every connected input from its source's output, all outputs read first */
static fmi2Status exchange(Link *links, size_t nl, fmi2Status st)
{
    size_t i;
    for (i = 0; i < nl; i++)
        st = worst(st, fmus[links[i].from].lib.GetReal(fmus[links[i].from].c, &links[i].from_vr, 1, &links[i].value));
    for (i = 0; i < nl && st <= fmi2Warning; i++)
        st = worst(st, fmus[links[i].to].lib.SetReal(fmus[links[i].to].c, &links[i].to_vr, 1, &links[i].value));
    return st;
}

static void usage(const char *msg)
{
    fprintf(stderr, "engine_host: %s\nusage: engine_host -n STEPS -s STEP [-t START] [-q] -F NAME=DIR:MODEL... "
                    "[-p NAME:VR=REAL]... [-I NAME:VR=INT]... [-c FROM:VR=TO:VR]... [-o NAME:VR]... [-i NAME:VR]...\n",
            msg);
    exit(2);
}

static int fmu_index(const char *name, size_t len)
{
    int k;
    for (k = 0; k < n_fmus; k++)
        if (strlen(fmus[k].name) == len && strncmp(fmus[k].name, name, len) == 0) return k;
    fprintf(stderr, "engine_host: no FMU named '%.*s' (declare it with -F before using it)\n", (int)len, name);
    exit(2);
}

static unsigned long parse_ulong(const char *s, const char *what)
{
    char *end;
    unsigned long v = strtoul(s, &end, 10);
    if (end == s || (*end != '\0' && *end != '=')) {
        fprintf(stderr, "engine_host: %s: '%s' is not a value reference\n", what, s);
        exit(2);
    }
    return v;
}

/* "NAME:VR" -> (fmu, vr); *rest -> after "=" if present */
static void parse_ref(const char *arg, int *fmu, fmi2ValueReference *vr, const char **rest, const char *what)
{
    const char *colon = strchr(arg, ':'), *eq;
    if (!colon) {
        fprintf(stderr, "engine_host: %s %s: expected NAME:VR\n", what, arg);
        exit(2);
    }
    *fmu = fmu_index(arg, (size_t)(colon - arg));
    *vr = (fmi2ValueReference)parse_ulong(colon + 1, what);
    eq = strchr(colon, '=');
    if (rest) {
        if (!eq) {
            fprintf(stderr, "engine_host: %s %s: expected NAME:VR=VALUE\n", what, arg);
            exit(2);
        }
        *rest = eq + 1;
    }
}

static double parse_double(const char *s, const char *what)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end != '\0') {
        fprintf(stderr, "engine_host: %s: '%s' is not a number\n", what, s);
        exit(2);
    }
    return v;
}

static void shutdown_all(fmi2Status st)
{
    int k;
    for (k = 0; k < n_fmus; k++) {
        if (fmus[k].c) {
            if (st <= fmi2Discard) fmus[k].lib.Terminate(fmus[k].c);
            if (st != fmi2Fatal) fmus[k].lib.FreeInstance(fmus[k].c);
            fmus[k].c = NULL;
        }
    }
    for (k = 0; k < n_fmus; k++) {
        fmi2_unload(&fmus[k].lib);
        free(fmus[k].guid);
    }
}

int main(int argc, char **argv)
{
    static RealSet ps[MAX_ITEMS];
    static IntSet is[MAX_ITEMS];
    static Link links[MAX_ITEMS];
    static Column cr[MAX_ITEMS], ci[MAX_ITEMS];
    size_t nps = 0, nis = 0, nl = 0, ncr = 0, nci = 0, i;
    long steps = -1, step;
    double h = 0.0, t0 = 0.0, t;
    int logging_on = fmi2True, k, code = 0, a;
    fmi2Status st = fmi2OK;
    char err[8192];

    for (a = 1; a < argc; a++) {
        const char *opt = argv[a], *val, *rest;
        if (opt[0] != '-' || opt[1] == '\0' || opt[2] != '\0') usage("unknown argument");
        if (opt[1] == 'q') {
            logging_on = fmi2False;
            continue;
        }
        if (a + 1 >= argc) usage("missing option value");
        val = argv[++a];
        if (nps >= MAX_ITEMS || nis >= MAX_ITEMS || nl >= MAX_ITEMS || ncr >= MAX_ITEMS || nci >= MAX_ITEMS)
            usage("too many items");
        switch (opt[1]) {
        case 'n': steps = (long)parse_ulong(val, "-n"); break;
        case 's': h = parse_double(val, "-s"); break;
        case 't': t0 = parse_double(val, "-t"); break;
        case 'F': {
            char *copy = (char *)malloc(strlen(val) + 1), *eq, *colon;
            if (!copy || n_fmus >= MAX_FMUS) usage("too many FMUs (at most 8)");
            strcpy(copy, val);
            eq = strchr(copy, '=');
            colon = eq ? strrchr(eq, ':') : NULL;
            if (!eq || !colon || colon == eq + 1) usage("-F: expected NAME=DIR:MODEL");
            *eq = *colon = '\0';
            fmus[n_fmus].name = copy;
            fmus[n_fmus].dir = eq + 1;
            fmus[n_fmus].model = colon + 1;
            n_fmus++;
            break;
        }
        case 'p':
            parse_ref(val, &ps[nps].fmu, &ps[nps].vr, &rest, "-p");
            ps[nps++].value = parse_double(rest, "-p");
            break;
        case 'I':
            parse_ref(val, &is[nis].fmu, &is[nis].vr, &rest, "-I");
            is[nis++].value = (fmi2Integer)parse_double(rest, "-I");
            break;
        case 'c':
            parse_ref(val, &links[nl].from, &links[nl].from_vr, &rest, "-c");
            parse_ref(rest, &links[nl].to, &links[nl].to_vr, NULL, "-c");
            nl++;
            break;
        case 'o': parse_ref(val, &cr[ncr].fmu, &cr[ncr].vr, NULL, "-o"); ncr++; break;
        case 'i': parse_ref(val, &ci[nci].fmu, &ci[nci].vr, NULL, "-i"); nci++; break;
        default: usage("unknown option");
        }
    }
    if (n_fmus == 0) usage("no FMU (-F)");
    if (steps < 0 || !(h > 0) || !isfinite(h)) usage("-n STEPS and -s STEP (finite, > 0) are required");

    /* load, instantiate, parameters, initialise */
    for (k = 0; k < n_fmus; k++) {
        char uri[8192];
        Fmu *f = &fmus[k];
        if (fmi2_load(&f->lib, f->dir, f->model, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "engine_host: %s: %s\n", f->name, err);
            shutdown_all(fmi2Error);
            return 1;
        }
        f->guid = fmi2_read_guid(f->dir);
        fmi2_resource_uri(f->dir, uri, sizeof uri);
        f->c = f->guid ? f->lib.Instantiate(f->name, fmi2CoSimulation, f->guid, uri, &host_callbacks, fmi2False,
                                            logging_on) : NULL;
        if (!f->c) {
            fprintf(stderr, "engine_host: %s: fmi2Instantiate failed (see the log above)\n", f->name);
            shutdown_all(fmi2Error);
            return 1;
        }
        st = worst(st, f->lib.SetupExperiment(f->c, fmi2False, 0.0, t0, fmi2True, t0 + (double)steps * h));
    }
    for (i = 0; i < nps; i++) st = worst(st, fmus[ps[i].fmu].lib.SetReal(fmus[ps[i].fmu].c, &ps[i].vr, 1, &ps[i].value));
    for (i = 0; i < nis; i++)
        st = worst(st, fmus[is[i].fmu].lib.SetInteger(fmus[is[i].fmu].c, &is[i].vr, 1, &is[i].value));
    for (k = 0; k < n_fmus; k++) st = worst(st, fmus[k].lib.EnterInitializationMode(fmus[k].c));
    /* the connections' initial values, as libcosim and OMSimulator propagate them: one pass per FMU carries a
     * value down any chain of connections (a loop needs an FMU whose initial outputs do not read its inputs) */
    for (k = 0; k < n_fmus && st <= fmi2Warning; k++) st = exchange(links, nl, st);
    for (k = 0; k < n_fmus; k++) st = worst(st, fmus[k].lib.ExitInitializationMode(fmus[k].c));
    if (st > fmi2Warning) {
        fprintf(stderr, "engine_host: initialisation returned %s\n", status_name(st));
        shutdown_all(st);
        return 1;
    }

    printf("time");
    for (i = 0; i < ncr; i++) printf(",%s:r%u", fmus[cr[i].fmu].name, cr[i].vr);
    for (i = 0; i < nci; i++) printf(",%s:i%u", fmus[ci[i].fmu].name, ci[i].vr);
    printf("\n");
    t = t0;
    for (step = 0;; step++) {
        /* Jacobi exchange at t: every input from the outputs at t, then the row */
        st = exchange(links, nl, st);
        if (st > fmi2Warning) {
            fprintf(stderr, "engine_host: the exchange at t = %.17g returned %s; stopping\n", t, status_name(st));
            code = st == fmi2Fatal ? 4 : 3;
            break;
        }
        printf("%.17g", t);
        for (i = 0; i < ncr; i++) {
            double v = NAN;
            fmus[cr[i].fmu].lib.GetReal(fmus[cr[i].fmu].c, &cr[i].vr, 1, &v);
            printf(",%.17g", v);
        }
        for (i = 0; i < nci; i++) {
            fmi2Integer v = 0;
            fmus[ci[i].fmu].lib.GetInteger(fmus[ci[i].fmu].c, &ci[i].vr, 1, &v);
            printf(",%d", v);
        }
        printf("\n");
        if (step == steps) break;
        for (k = 0; k < n_fmus; k++) {
            fmi2Status s = fmus[k].lib.DoStep(fmus[k].c, t, h, fmi2True);
            if (s > fmi2Warning) {
                fmi2Boolean terminated = fmi2False;
                if (s == fmi2Discard) fmus[k].lib.GetBooleanStatus(fmus[k].c, fmi2Terminated, &terminated);
                fprintf(stderr, "engine_host: %s: fmi2DoStep(%.17g, %.17g) returned %s%s; stopping\n", fmus[k].name,
                        t, h, status_name(s), terminated ? " (fmi2Terminated)" : "");
                st = s;
                break;
            }
        }
        if (st > fmi2Warning) {
            code = st == fmi2Fatal ? 4 : 3;
            break;
        }
        t = t0 + (double)(step + 1) * h;
    }
    fflush(stdout);
    shutdown_all(st);
    fprintf(stderr, "engine_host: done, exit status %d\n", code);
    return code;
}
