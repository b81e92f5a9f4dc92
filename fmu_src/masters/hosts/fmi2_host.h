/*
 * fmi2_host.h - what a native FMI 2.0 co-simulation master needs to load and drive an extracted FMU: the
 * FMI 2.0 types and function types it uses (the standard's default platform types, declared here so that
 * nothing else is needed), loading the binary of this platform (dlopen, or LoadLibrary on Windows),
 * reading the GUID, a logger, a clock. Shared by fmu_host.c (one FMU) and engine_host.c (a system of
 * FMUs); header-only, everything static.
 */
#ifndef ROTORUB_FMI2_HOST_H
#define ROTORUB_FMI2_HOST_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif

/* ---------------------------------------------------------------- FMI 2.0 declarations */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef struct {
    void *lib;
    char path[4096];
    const char *(*GetVersion)(void);
    fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                 fmi2Boolean, fmi2Boolean);
    void (*FreeInstance)(fmi2Component);
    fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
    fmi2Status (*EnterInitializationMode)(fmi2Component);
    fmi2Status (*ExitInitializationMode)(fmi2Component);
    fmi2Status (*Terminate)(fmi2Component);
    fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
    fmi2Status (*SetString)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2String[]);
    fmi2Status (*SetInteger)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[]);
    fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
    fmi2Status (*GetInteger)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]);
    fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
    fmi2Status (*GetBooleanStatus)(fmi2Component, const fmi2StatusKind, fmi2Boolean *);
    fmi2Status (*GetRealStatus)(fmi2Component, const fmi2StatusKind, fmi2Real *);
} fmi2_lib;

/* the FMI binaries/ folder and library suffix of the platform this host is compiled for */
#if defined(_WIN32)
#define HOST_PLATFORM "win64"
#define HOST_SUFFIX ".dll"
#elif defined(__APPLE__) && defined(__aarch64__)
#define HOST_PLATFORM "aarch64-darwin"
#define HOST_SUFFIX ".dylib"
#elif defined(__APPLE__)
#define HOST_PLATFORM "darwin64"
#define HOST_SUFFIX ".dylib"
#elif defined(__aarch64__)
#define HOST_PLATFORM "aarch64-linux"
#define HOST_SUFFIX ".so"
#else
#define HOST_PLATFORM "linux64"
#define HOST_SUFFIX ".so"
#endif

static inline const char *status_name(fmi2Status s)
{
    static const char *names[] = {"fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending"};
    return (s >= fmi2OK && s <= fmi2Pending) ? names[s] : "fmi2Status(?)";
}

static inline fmi2Status worst(fmi2Status a, fmi2Status b) { return a > b ? a : b; }

/* ---------------------------------------------------------------- callbacks */
static inline void host_logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                        fmi2String message, ...)
{
    va_list ap;
    (void)env;
    fprintf(stderr, "[log] %s %s %s: ", instance ? instance : "?", status_name(status), category ? category : "");
    va_start(ap, message);
    vfprintf(stderr, message ? message : "(null)", ap);
    va_end(ap);
    fputc('\n', stderr);
    fflush(stderr);
}

static inline void *host_alloc(size_t n, size_t size) { return calloc(n, size); }

static const fmi2CallbackFunctions host_callbacks = {host_logger, host_alloc, free, NULL, NULL};

/* seconds on a monotonic clock */
static inline double host_now(void)
{
#ifdef _WIN32
    LARGE_INTEGER f, c;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&c);
    return (double)c.QuadPart / (double)f.QuadPart;
#else
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
}

/* ---------------------------------------------------------------- files */
static inline char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *buf;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = (char *)malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf) buf[n] = '\0';
    fclose(f);
    return buf;
}

/* the guid="..." attribute of <fmiModelDescription> (first occurrence in the file) */
static inline char *fmi2_read_guid(const char *dir)
{
    char path[4096], *xml, *p, *guid = NULL;
    snprintf(path, sizeof path, "%s/modelDescription.xml", dir);
    xml = read_file(path);
    if (!xml) return NULL;
    p = strstr(xml, " guid=\"");
    if (p) {
        char *q;
        p += 7;
        q = strchr(p, '"');
        if (q) {
            guid = (char *)malloc((size_t)(q - p) + 1);
            if (guid) {
                memcpy(guid, p, (size_t)(q - p));
                guid[q - p] = '\0';
            }
        }
    }
    free(xml);
    return guid;
}

/* the file:// URI of DIR/resources (only ' ' is escaped: what pythonfmu decodes) */
static inline void fmi2_resource_uri(const char *dir, char *out, size_t len)
{
    size_t k = (size_t)snprintf(out, len, "file://");
    const char *c;
    for (c = dir; *c && k + 4 < len; c++) k += (size_t)(*c == ' ' ? snprintf(out + k, 4, "%%20") : snprintf(out + k, 2, "%c", *c));
    snprintf(out + k, len - k, "/resources");
}

/* ---------------------------------------------------------------- loading */
static inline void *sym(void *lib, const char *name)
{
#ifdef _WIN32
    return (void *)GetProcAddress((HMODULE)lib, name);
#else
    return dlsym(lib, name);
#endif
}

static inline const char *load_error(void)
{
#ifdef _WIN32
    static char buf[64];
    snprintf(buf, sizeof buf, "Windows error %lu", (unsigned long)GetLastError());
    return buf;
#else
    return dlerror();
#endif
}

/* Load DIR/binaries/PLATFORM/MODEL<suffix> (platform NULL: this host's) and resolve the functions; 0, or -1 with
 * the reason in err. */
static inline int fmi2_load(fmi2_lib *f, const char *dir, const char *model, const char *platform, char *err, size_t len)
{
    memset(f, 0, sizeof *f);
    snprintf(f->path, sizeof f->path, "%s/binaries/%s/%s%s", dir, platform ? platform : HOST_PLATFORM, model,
             HOST_SUFFIX);
#ifdef _WIN32
    f->lib = (void *)LoadLibraryA(f->path);
#else
    f->lib = dlopen(f->path, RTLD_NOW | RTLD_LOCAL);
#endif
    if (!f->lib) {
        snprintf(err, len, "cannot load %s: %s", f->path, load_error());
        return -1;
    }
#define RESOLVE(field, name)                                                                                           \
    do {                                                                                                               \
        *(void **)(&f->field) = sym(f->lib, name);                                                                     \
        if (!f->field) {                                                                                               \
            snprintf(err, len, "%s does not export %s", f->path, name);                                               \
            return -1;                                                                                                 \
        }                                                                                                              \
    } while (0)
    RESOLVE(GetVersion, "fmi2GetVersion");
    RESOLVE(Instantiate, "fmi2Instantiate");
    RESOLVE(FreeInstance, "fmi2FreeInstance");
    RESOLVE(SetupExperiment, "fmi2SetupExperiment");
    RESOLVE(EnterInitializationMode, "fmi2EnterInitializationMode");
    RESOLVE(ExitInitializationMode, "fmi2ExitInitializationMode");
    RESOLVE(Terminate, "fmi2Terminate");
    RESOLVE(SetReal, "fmi2SetReal");
    RESOLVE(SetString, "fmi2SetString");
    RESOLVE(SetInteger, "fmi2SetInteger");
    RESOLVE(GetReal, "fmi2GetReal");
    RESOLVE(GetInteger, "fmi2GetInteger");
    RESOLVE(DoStep, "fmi2DoStep");
    RESOLVE(GetBooleanStatus, "fmi2GetBooleanStatus");
    RESOLVE(GetRealStatus, "fmi2GetRealStatus");
#undef RESOLVE
    return 0;
}

/* The end of the FMU library's use, on every path after it was loaded.
 * pythonfmu FMUs export finalizePythonInterpreter(). Without that call the interpreter they started is finalized
 * by an exit-time destructor of the FMU library, which runs after the exit-time destructors of the libraries
 * loaded after it (the C/C++ extension modules of scipy, numba/llvmlite, ...): Py_Finalize then crashes
 * intermittently with this FMU (heap corruption, SIGSEGV after the results are written). Finalizing here, while
 * everything is intact, avoids it. Call it once, after the last fmi2FreeInstance of every pythonfmu FMU of the
 * process: the interpreter cannot be restarted (numpy cannot be imported twice). No-op for other FMUs. */
static inline void fmi2_unload(fmi2_lib *f)
{
    void (*finalize_python)(void);
    if (!f->lib) return;
    *(void **)(&finalize_python) = sym(f->lib, "finalizePythonInterpreter");
    if (finalize_python && !getenv("FMU_HOST_NO_FINALIZE")) finalize_python();
#ifdef _WIN32
    FreeLibrary((HMODULE)f->lib);
#else
    if (dlclose(f->lib) != 0) fprintf(stderr, "fmu_host: dlclose: %s\n", dlerror());
#endif
    f->lib = NULL;
}

#endif
