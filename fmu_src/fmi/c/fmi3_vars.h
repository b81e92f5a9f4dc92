/*
 * fmi3_vars.h: the FMI 3.0 variables of a model, as runs of the FMI 2.0 value slots its model works on
 * (fmu_model.h): a scalar is one slot, an array the slots of its elements in order. The build generates the table
 * (FMI3_INFO, fmu_src/fmi/csource.py) next to MODEL_INFO from the same variable list (a model's variables.py),
 * so the FMI 2.0 and 3.0 FMUs of a model share every range, start value and rule, and the model is the same
 * file.
 */
#ifndef ROTORUB_FMI3_VARS_H
#define ROTORUB_FMI3_VARS_H

typedef enum { V3_FLOAT64, V3_INT32, V3_UINT64, V3_ENUM, V3_STRING } v3_type;
typedef enum {
    K3_SLOTS,      /* the values of slots[0 .. n-1] */
    K3_TIME,       /* the independent variable: the FMU's time */
    K3_STRUCTURAL, /* a structural parameter fixed by the build (an array's size): the value 'fixed' */
    K3_SUM         /* a local computed from two slots: r[slots[0]] + r[slots[1]] (an event indicator) */
} v3_kind;

typedef struct {
    unsigned vr;
    const char *name;
    v3_type type;
    v3_kind kind;
    int n;            /* elements (1: a scalar) */
    const int *slots; /* K3_SLOTS: n slots; K3_SUM: 2 */
    unsigned long long fixed; /* K3_STRUCTURAL */
} fmi3_var;

typedef struct {
    int n_vars;
    const fmi3_var *vars;
    unsigned max_vr;
    const int *by_vr; /* value reference -> index in vars, or -1 (max_vr + 1 entries) */
} fmi3_info;

extern const fmi3_info FMI3_INFO;

#endif
