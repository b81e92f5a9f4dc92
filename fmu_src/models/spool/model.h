/*
 * model.h: LPSpool's model (model.c). Its value references are variables.h's (VR_<NAME>, generated from
 * fmu_src/models/spool/variables.py); it writes nothing beyond fmu_model.h's defaults (no rule between variables
 * but their ranges, no events, a refused step leaves the state as it was).
 */
#ifndef ROTORUB_SPOOL_MODEL_H
#define ROTORUB_SPOOL_MODEL_H

#include "fmu_model.h"
#include "variables.h"

#endif
