/*
 * Unit labels of measurement files (UFF record-9/10 labels, CSV and WAV
 * channel units) -> quantity and factor to SI. One table, used by the FRF
 * reader (uff58_read.c) and by the signal readers (src/signals/).
 */
#include <string.h>

#include "core/rcb_internal.h"

typedef struct unit_row {
  const char *label;
  rcb_quantity q;
  double to_si;
} unit_row;

static const unit_row units[] = {
    {"m", RCB_QTY_DISPLACEMENT, 1.0},
    {"mm", RCB_QTY_DISPLACEMENT, 1e-3},
    {"um", RCB_QTY_DISPLACEMENT, 1e-6},
    {"\xc2\xb5m", RCB_QTY_DISPLACEMENT, 1e-6}, /* UTF-8 micro sign */
    {"micron", RCB_QTY_DISPLACEMENT, 1e-6},
    {"mil", RCB_QTY_DISPLACEMENT, 25.4e-6},
    {"in", RCB_QTY_DISPLACEMENT, 0.0254},
    {"m/s", RCB_QTY_VELOCITY, 1.0},
    {"mm/s", RCB_QTY_VELOCITY, 1e-3},
    {"um/s", RCB_QTY_VELOCITY, 1e-6},
    {"in/s", RCB_QTY_VELOCITY, 0.0254},
    {"m/s^2", RCB_QTY_ACCELERATION, 1.0},
    {"m/s2", RCB_QTY_ACCELERATION, 1.0},
    {"m/s**2", RCB_QTY_ACCELERATION, 1.0},
    {"mm/s^2", RCB_QTY_ACCELERATION, 1e-3},
    {"mm/s2", RCB_QTY_ACCELERATION, 1e-3},
    {"g", RCB_QTY_ACCELERATION, 9.80665}, /* standard gravity (CGPM 1901) */
    {"N", RCB_QTY_FORCE, 1.0},
    {"kN", RCB_QTY_FORCE, 1e3},
    {"lbf", RCB_QTY_FORCE, 4.4482216152605},
    /* Rotation channels (rot_x, rot_y) and moments, as the UFF writer labels
     * them: the quantity is the order of the derivative, rad for m. */
    {"rad", RCB_QTY_DISPLACEMENT, 1.0},
    {"mrad", RCB_QTY_DISPLACEMENT, 1e-3},
    {"rad/s", RCB_QTY_VELOCITY, 1.0},
    {"rad/s^2", RCB_QTY_ACCELERATION, 1.0},
    {"rad/s2", RCB_QTY_ACCELERATION, 1.0},
    {"N m", RCB_QTY_FORCE, 1.0},
    {"Nm", RCB_QTY_FORCE, 1.0},
    {"N*m", RCB_QTY_FORCE, 1.0},
    {"V", RCB_QTY_VOLTAGE, 1.0},
    {"mV", RCB_QTY_VOLTAGE, 1e-3},
};

int rcb_unit_parse(const char *label, rcb_quantity *q, double *to_si) {
  size_t i, a = 0, b;
  if (!label || !q || !to_si) return -1;
  b = strlen(label);
  while (a < b && (label[a] == ' ' || label[a] == '\t')) a++;
  while (b > a && (label[b - 1] == ' ' || label[b - 1] == '\t')) b--;
  for (i = 0; i < sizeof units / sizeof units[0]; i++)
    if (strlen(units[i].label) == b - a && strncmp(units[i].label, label + a, b - a) == 0) {
      *q = units[i].q;
      *to_si = units[i].to_si;
      return 0;
    }
  return -1;
}

const char *rcb_quantity_name(rcb_quantity q) {
  static const char *const names[] = {"unknown", "displacement", "velocity", "acceleration",
                                      "force", "voltage"};
  return (unsigned)q <= RCB_QTY_VOLTAGE ? names[q] : "unknown";
}
