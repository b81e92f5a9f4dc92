/*
 * model.h: CasingLoad's model (model.c). Its value references are variables.h's (VR_<NAME>, generated from
 * fmu_src/models/casing_load/variables.py); it writes nothing beyond fmu_model.h's defaults (no rule between
 * variables but their ranges, no events, a step never fails).
 */
#ifndef ROTORUB_CASING_LOAD_MODEL_H
#define ROTORUB_CASING_LOAD_MODEL_H

#include "fmu_model.h"
#include "variables.h"

#endif
