/*
 * fmu_host.c - a minimal native (non-Python) FMI 2.0 co-simulation master.
 *
 * It loads an *extracted* FMU's shared library (dlopen; LoadLibrary when built for Windows), drives one
 * instance through
 * the FMI 2.0 co-simulation calling sequence and prints a CSV of the selected outputs.
 * Written for fmus/RotorCasingContact.fmu (a pythonfmu FMU, see docs/FMU-hosts.md) but
 * generic: value references come from the command line, nothing is model specific.
 *
 *   gcc -O2 -Wall -o fmu_host fmu_host.c -ldl     (any C99 compiler; `zig cc -target x86_64-windows-gnu`
 *                                                 builds the win64 host that runs the win64 binary under wine)
 *
 *   fmu_host -d DIR [-m MODEL] [-P PLATFORM] [-L LIBPYTHON] [-n STEPS] [-s STEP] [-t START] [-q]
 *            [-p VR=REAL]... [-I VR=INT]... [-S VR=STRING]... [-u VR=V0[:V1]]... [-e K:VR=REAL]...
 *            [-o VR]... [-i VR]...
 *
 *   -d DIR        folder the .fmu was unzipped into (holds modelDescription.xml)
 *   -m MODEL      modelIdentifier (default RotorCasingContact): binaries/PLATFORM/MODEL.so (.dll, .dylib)
 *   -P PLATFORM   the binaries/ folder (default: the platform the host is built for, e.g. linux64)
 *   -L LIBPYTHON  dlopen this library with RTLD_GLOBAL before the FMU (a pythonfmu FMU does
 *                 not link libpython; the alternative is LD_PRELOAD=LIBPYTHON)
 *   -n STEPS      number of communication steps (default 10)
 *   -s STEP       communication step size in s (default 1e-3)
 *   -t START      start time in s (default 0)
 *   -p VR=REAL    fmi2SetReal before fmi2EnterInitializationMode (parameters, start values)
 *   -I VR=INT     fmi2SetInteger before fmi2EnterInitializationMode (Integer, Enumeration)
 *   -S VR=STRING  fmi2SetString before fmi2EnterInitializationMode
 *   -u VR=V0[:V1] real input set before every fmi2DoStep and held over the step:
 *                 V0 + (V1 - V0) * k / (STEPS - 1) at step k = 0..STEPS-1 (V0 if V1 omitted)
 *   -e K:VR=REAL  from step K on, the input (or tunable parameter) VR is REAL (overrides -u)
 *   -o VR / -i VR Real / Integer variable printed as a CSV column (in the order given)
 *   -b            benchmark: print no rows; time the stepping loop (set the inputs, fmi2DoStep, read the
 *                 outputs) and instantiate .. end of the first step, on stderr
 *   -q            loggingOn = fmi2False (default: fmi2True; pythonfmu forwards the slave's
 *                 log messages only when logging is on)
 *
 * Output (stdout): a header "time,fmi2status,u<vr>...,r<vr>...,i<vr>..." then one row after
 * initialization (time = START, fmi2status = the worst status of the initialization calls)
 * and one row after every fmi2DoStep (time = end of the step, the status it returned, the
 * inputs held over the step, the outputs read after it). Reals are printed with %.17g (they
 * round-trip exactly). Log messages go to stderr as "[log] <instance> <status> <category>: msg".
 *
 * Environment: FMU_HOST_NO_FINALIZE=1 skips the call of the FMU's finalizePythonInterpreter() before exit (see
 * fmi2_unload() in fmi2_host.h; only there to demonstrate why the call is needed).
 *
 * A step that does not return fmi2OK/fmi2Warning ends the run: the host reports it on stderr,
 * calls fmi2Terminate (after fmi2Discard) and fmi2FreeInstance, and exits with status 3
 * (4 for fmi2Fatal). Exit status 0: every step succeeded; 1: the FMU could not be loaded,
 * instantiated or initialized; 2: bad command line.
 */

#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L
#endif
#include <math.h>

#include "fmi2_host.h"

static fmi2_lib fmi;

/* ---------------------------------------------------------------- command line */
#define MAX_VARS 256

typedef struct { fmi2ValueReference vr; double v0, v1; } Input;
typedef struct { long step; fmi2ValueReference vr; double value; } Event;
typedef struct { fmi2ValueReference vr; const char *value; } StrParam;

static void usage(const char *msg)
{
    fprintf(stderr, "fmu_host: %s\nusage: fmu_host -d DIR [-m MODEL] [-P PLATFORM] [-L LIBPYTHON] [-n STEPS] [-s STEP] [-t START] "
                    "[-q] [-b] [-p VR=REAL]... [-I VR=INT]... [-S VR=STRING]... [-u VR=V0[:V1]]... [-e K:VR=REAL]... [-o VR]... "
                    "[-i VR]...\n",
            msg);
    exit(2);
}

static double parse_double(const char *s, const char *what)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end != '\0') {
        fprintf(stderr, "fmu_host: %s: '%s' is not a number\n", what, s);
        exit(2);
    }
    return v;
}

static long parse_long(const char *s, const char *what)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || v < 0) {
        fprintf(stderr, "fmu_host: %s: '%s' is not a non-negative integer\n", what, s);
        exit(2);
    }
    return v;
}

/* "VR=rest": returns VR, *rest points after '=' */
static fmi2ValueReference parse_vr_assign(char *arg, char **rest, const char *opt)
{
    char *eq = strchr(arg, '=');
    if (!eq) {
        fprintf(stderr, "fmu_host: %s %s: expected VR=VALUE\n", opt, arg);
        exit(2);
    }
    *eq = '\0';
    *rest = eq + 1;
    return (fmi2ValueReference)parse_long(arg, opt);
}

/* ---------------------------------------------------------------- main */
int main(int argc, char **argv)
{
    const char *dir = NULL, *model = "RotorCasingContact", *libpython = NULL, *platform = NULL;
    long steps = 10;
    double h = 1e-3, t0 = 0.0;
    int logging_on = fmi2True, bench = 0;
    double ts0 = 0.0, ts1 = 0.0, ts2 = 0.0;
    char err[8192];
    static fmi2ValueReference pr_vr[MAX_VARS], pi_vr[MAX_VARS], out_r[MAX_VARS], out_i[MAX_VARS];
    static double pr_val[MAX_VARS];
    static fmi2Integer pi_val[MAX_VARS];
    static StrParam ps[MAX_VARS];
    static Input in[MAX_VARS];
    static Event ev[MAX_VARS];
    size_t npr = 0, npi = 0, nps = 0, nin = 0, nev = 0, nor = 0, noi = 0;

    for (int a = 1; a < argc; a++) {
        const char *opt = argv[a];
        if (opt[0] != '-' || opt[1] == '\0' || opt[2] != '\0') usage("unknown argument");
        if (opt[1] == 'q') {
            logging_on = fmi2False;
            continue;
        }
        if (opt[1] == 'b') {
            bench = 1;
            continue;
        }
        if (a + 1 >= argc) usage("missing option value");
        char *val = argv[++a], *rest;
        if (npr >= MAX_VARS || npi >= MAX_VARS || nps >= MAX_VARS || nin >= MAX_VARS || nev >= MAX_VARS || nor >= MAX_VARS ||
            noi >= MAX_VARS)
            usage("too many variables");
        switch (opt[1]) {
        case 'd': dir = val; break;
        case 'm': model = val; break;
        case 'P': platform = val; break;
        case 'L': libpython = val; break;
        case 'n': steps = parse_long(val, "-n"); break;
        case 's': h = parse_double(val, "-s"); break;
        case 't': t0 = parse_double(val, "-t"); break;
        case 'p':
            pr_vr[npr] = parse_vr_assign(val, &rest, "-p");
            pr_val[npr++] = parse_double(rest, "-p");
            break;
        case 'I':
            pi_vr[npi] = parse_vr_assign(val, &rest, "-I");
            pi_val[npi++] = (fmi2Integer)parse_long(rest, "-I");
            break;
        case 'S':
            ps[nps].vr = parse_vr_assign(val, &rest, "-S");
            ps[nps++].value = rest;
            break;
        case 'u': {
            in[nin].vr = parse_vr_assign(val, &rest, "-u");
            char *colon = *rest ? strchr(rest + 1, ':') : NULL; /* a leading '-' sign is not a separator */
            if (colon) {
                *colon = '\0';
                in[nin].v1 = parse_double(colon + 1, "-u");
            }
            in[nin].v0 = parse_double(rest, "-u");
            if (!colon) in[nin].v1 = in[nin].v0;
            nin++;
            break;
        }
        case 'e': {
            char *colon = strchr(val, ':');
            if (!colon) usage("-e: expected K:VR=VALUE");
            *colon = '\0';
            ev[nev].step = parse_long(val, "-e");
            ev[nev].vr = parse_vr_assign(colon + 1, &rest, "-e");
            ev[nev++].value = parse_double(rest, "-e");
            break;
        }
        case 'o': out_r[nor++] = (fmi2ValueReference)parse_long(val, "-o"); break;
        case 'i': out_i[noi++] = (fmi2ValueReference)parse_long(val, "-i"); break;
        default: usage("unknown option");
        }
    }
    if (!dir) usage("-d DIR is required");
    if (!(h > 0) || !isfinite(h)) usage("-s: the step size must be finite and > 0");

    /* 1. libpython first, with its symbols global, then the FMU's library */
#ifndef _WIN32
    if (libpython && !dlopen(libpython, RTLD_NOW | RTLD_GLOBAL)) {
        fprintf(stderr, "fmu_host: cannot load %s: %s\n", libpython, dlerror());
        return 1;
    }
#else
    if (libpython) usage("-L: not on Windows (load the FMU's Python DLLs through PATH)");
#endif
    if (fmi2_load(&fmi, dir, model, platform, err, sizeof err) != 0) {
        fprintf(stderr, "fmu_host: %s\n", err);
        fprintf(stderr, "fmu_host: hint: a pythonfmu FMU needs libpython3.X.so loaded first "
                        "(LD_PRELOAD=/path/to/libpython3.X.so or -L /path/to/libpython3.X.so)\n");
        fmi2_unload(&fmi);
        return 1;
    }
    fprintf(stderr, "fmu_host: loaded %s (FMI %s)\n", fmi.path, fmi.GetVersion());

    /* 2. instantiate: GUID from modelDescription.xml, resources as a file:// URI */
    char *guid = fmi2_read_guid(dir);
    if (!guid) {
        fprintf(stderr, "fmu_host: no guid in %s/modelDescription.xml\n", dir);
        return 1;
    }
    char resources[8192];
    fmi2_resource_uri(dir, resources, sizeof resources);

    ts0 = host_now();
    fmi2Component c = fmi.Instantiate("host", fmi2CoSimulation, guid, resources, &host_callbacks, fmi2False,
                                      logging_on);
    if (!c) {
        fprintf(stderr, "fmu_host: fmi2Instantiate failed (see the log above)\n");
        fmi2_unload(&fmi);
        return 1;
    }

    /* 3. parameters and start values, initialization */
    fmi2Status st = fmi.SetupExperiment(c, fmi2False, 0.0, t0, fmi2False, 0.0);
    for (size_t i = 0; i < npr; i++) st = worst(st, fmi.SetReal(c, &pr_vr[i], 1, &pr_val[i]));
    for (size_t i = 0; i < npi; i++) st = worst(st, fmi.SetInteger(c, &pi_vr[i], 1, &pi_val[i]));
    for (size_t i = 0; i < nps; i++) st = worst(st, fmi.SetString(c, &ps[i].vr, 1, &ps[i].value));
    double *u = calloc(nin + 1, sizeof *u);
    for (size_t i = 0; i < nin; i++) {
        u[i] = in[i].v0;
        st = worst(st, fmi.SetReal(c, &in[i].vr, 1, &u[i]));
    }
    st = worst(st, fmi.EnterInitializationMode(c));
    st = worst(st, fmi.ExitInitializationMode(c));
    if (st > fmi2Warning) {
        fprintf(stderr, "fmu_host: initialization returned %s\n", status_name(st));
        if (st != fmi2Fatal) fmi.FreeInstance(c);
        fmi2_unload(&fmi);
        return 1;
    }

    /* 4. the stepping loop */
    double *r = calloc(nor + 1, sizeof *r);
    fmi2Integer *iv = calloc(noi + 1, sizeof *iv);
    if (!bench) {
        printf("time,fmi2status");
        for (size_t i = 0; i < nin; i++) printf(",u%u", in[i].vr);
        for (size_t i = 0; i < nor; i++) printf(",r%u", out_r[i]);
        for (size_t i = 0; i < noi; i++) printf(",i%u", out_i[i]);
        printf("\n");
    }

    int exit_code = 0;
    fmi2Status set_st = fmi2OK;
    double t = t0, t_start = t0;
    for (long step = 0; step <= steps; step++) {
        if (step > 0) {
            t_start = t;
            st = fmi.DoStep(c, t, h, fmi2True);
            t = t0 + (double)step * h;
            if (step == 1) ts1 = host_now();
        }
        int readable = st <= fmi2Discard; /* outputs may be inspected after fmi2Discard */
        fmi2Status get_st = fmi2OK;
        if (readable && nor) get_st = fmi.GetReal(c, out_r, nor, r);
        if (readable && noi && get_st <= fmi2Warning) get_st = worst(get_st, fmi.GetInteger(c, out_i, noi, iv));
        readable = readable && get_st <= fmi2Warning;
        if (!bench) {
            printf("%.17g,%d", t, (int)st);
            for (size_t i = 0; i < nin; i++) printf(",%.17g", u[i]);
            for (size_t i = 0; i < nor; i++) printf(readable ? ",%.17g" : ",nan", r[i]);
            for (size_t i = 0; i < noi; i++) readable ? printf(",%d", iv[i]) : printf(",");
            printf("\n");
        }
        if (st > fmi2Warning) {
            fprintf(stderr, "fmu_host: fmi2DoStep(%.17g, %.17g) returned %s; stopping\n", t_start, h,
                    status_name(st));
            exit_code = st == fmi2Fatal ? 4 : 3;
            break;
        }
        if (get_st > fmi2Warning) { /* e.g. a value reference of the wrong type */
            fprintf(stderr, "fmu_host: reading the outputs at t = %.17g returned %s; stopping\n", t,
                    status_name(get_st));
            st = get_st;
            exit_code = st == fmi2Fatal ? 4 : 3;
            break;
        }
        if (step == steps) break;
        /* inputs held over step `step` (the interval [t, t + h]) */
        for (size_t i = 0; i < nin; i++) {
            double v = steps > 1 ? in[i].v0 + (in[i].v1 - in[i].v0) * (double)step / (double)(steps - 1) : in[i].v0;
            for (size_t e = 0; e < nev; e++)
                if (ev[e].vr == in[i].vr && ev[e].step <= step) v = ev[e].value;
            u[i] = v;
            set_st = worst(set_st, fmi.SetReal(c, &in[i].vr, 1, &u[i]));
        }
        for (size_t e = 0; e < nev; e++) { /* events on variables that are not -u inputs */
            int is_input = 0;
            for (size_t i = 0; i < nin; i++) is_input |= in[i].vr == ev[e].vr;
            if (!is_input && ev[e].step == step) set_st = worst(set_st, fmi.SetReal(c, &ev[e].vr, 1, &ev[e].value));
        }
        if (set_st > fmi2Warning) {
            fprintf(stderr, "fmu_host: fmi2SetReal before the step at t = %.17g returned %s; stopping\n", t,
                    status_name(set_st));
            st = set_st;
            exit_code = st == fmi2Fatal ? 4 : 3;
            break;
        }
        fflush(stdout);
    }
    fflush(stdout);
    ts2 = host_now();
    if (bench && steps > 1)
        fprintf(stderr, "fmu_host: bench: instantiate to end of first step %.6f s; steps 2..%ld: %.9f s per step\n",
                ts1 - ts0, steps, (ts2 - ts1) / (double)(steps - 1));

    /* 5. shut down: fmi2Terminate is not allowed after fmi2Error/fmi2Fatal; fmi2FreeInstance is, after Error */
    if (st <= fmi2Discard) {
        fmi2Status ts = fmi.Terminate(c);
        if (ts > fmi2Warning) fprintf(stderr, "fmu_host: fmi2Terminate returned %s\n", status_name(ts));
    }
    if (st != fmi2Fatal) fmi.FreeInstance(c);
    free(u);
    free(r);
    free(iv);
    free(guid);
    fmi2_unload(&fmi);
    fprintf(stderr, "fmu_host: done, exit status %d\n", exit_code);
    return exit_code;
}
