/*
 * Unit labels of measurement files (UFF record-9/10 labels, CSV and WAV
 * channel units) -> quantity and factor to SI. One table, used by the FRF
 * reader (uff58_read.c) and by the signal readers (src/signals/).
 */
#include <stdio.h>
#include <string.h>

#include "core/rcb_internal.h"

typedef struct unit_row {
  const char *label;
  rcb_quantity q;
  double to_si;
  int alias; /* another spelling of the row above: left out of rcb_unit_list */
} unit_row;

/* Vendor files spell the superscript 2 and the micro sign in UTF-8 or in
 * Latin-1 (one byte, 0xB2 and 0xB5): both are here (issue #25, the UFF
 * files of acquisition systems). */
static const unit_row units[] = {
    {"m", RCB_QTY_DISPLACEMENT, 1.0, 0},
    {"mm", RCB_QTY_DISPLACEMENT, 1e-3, 0},
    {"um", RCB_QTY_DISPLACEMENT, 1e-6, 0},
    {"\xc2\xb5m", RCB_QTY_DISPLACEMENT, 1e-6, 1}, /* UTF-8 micro sign */
    {"\xb5m", RCB_QTY_DISPLACEMENT, 1e-6, 1},     /* Latin-1 micro sign */
    {"micron", RCB_QTY_DISPLACEMENT, 1e-6, 1},
    {"mil", RCB_QTY_DISPLACEMENT, 25.4e-6, 0},
    {"mils", RCB_QTY_DISPLACEMENT, 25.4e-6, 1},
    {"in", RCB_QTY_DISPLACEMENT, 0.0254, 0},
    {"m/s", RCB_QTY_VELOCITY, 1.0, 0},
    {"mm/s", RCB_QTY_VELOCITY, 1e-3, 0},
    {"um/s", RCB_QTY_VELOCITY, 1e-6, 0},
    {"in/s", RCB_QTY_VELOCITY, 0.0254, 0},
    {"ips", RCB_QTY_VELOCITY, 0.0254, 1},
    {"m/s^2", RCB_QTY_ACCELERATION, 1.0, 0},
    {"m/s2", RCB_QTY_ACCELERATION, 1.0, 1},
    {"m/s**2", RCB_QTY_ACCELERATION, 1.0, 1},
    {"m/s\xc2\xb2", RCB_QTY_ACCELERATION, 1.0, 1}, /* UTF-8 superscript two */
    {"m/s\xb2", RCB_QTY_ACCELERATION, 1.0, 1},     /* Latin-1 superscript two */
    {"mm/s^2", RCB_QTY_ACCELERATION, 1e-3, 0},
    {"mm/s2", RCB_QTY_ACCELERATION, 1e-3, 1},
    {"mm/s\xc2\xb2", RCB_QTY_ACCELERATION, 1e-3, 1},
    {"mm/s\xb2", RCB_QTY_ACCELERATION, 1e-3, 1},
    {"g", RCB_QTY_ACCELERATION, 9.80665, 0}, /* standard gravity (CGPM 1901) */
    {"N", RCB_QTY_FORCE, 1.0, 0},
    {"kN", RCB_QTY_FORCE, 1e3, 0},
    {"lbf", RCB_QTY_FORCE, 4.4482216152605, 0},
    /* Rotation channels (rot_x, rot_y) and moments, as the UFF writer labels
     * them: the quantity is the order of the derivative, rad for m. */
    {"rad", RCB_QTY_DISPLACEMENT, 1.0, 0},
    {"mrad", RCB_QTY_DISPLACEMENT, 1e-3, 0},
    {"rad/s", RCB_QTY_VELOCITY, 1.0, 0},
    {"rad/s^2", RCB_QTY_ACCELERATION, 1.0, 0},
    {"rad/s2", RCB_QTY_ACCELERATION, 1.0, 1},
    {"N m", RCB_QTY_FORCE, 1.0, 0},
    {"Nm", RCB_QTY_FORCE, 1.0, 1},
    {"N*m", RCB_QTY_FORCE, 1.0, 1},
    {"V", RCB_QTY_VOLTAGE, 1.0, 0},
    {"mV", RCB_QTY_VOLTAGE, 1e-3, 0},
    {"Pa", RCB_QTY_PRESSURE, 1.0, 0},
    {"kPa", RCB_QTY_PRESSURE, 1e3, 0},
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

size_t rcb_unit_list(rcb_quantity q, char *buf, size_t size) {
  size_t i, at = 0;
  if (buf && size) buf[0] = '\0';
  for (i = 0; i < sizeof units / sizeof units[0]; i++) {
    int k;
    if (units[i].alias || (q != RCB_QTY_UNKNOWN && units[i].q != q)) continue;
    k = snprintf(buf && at < size ? buf + at : NULL, buf && at < size ? size - at : 0, "%s%s",
                 at ? ", " : "", units[i].label);
    at += k > 0 ? (size_t)k : 0;
  }
  return at;
}

const char *rcb_quantity_name(rcb_quantity q) {
  static const char *const names[] = {"unknown", "displacement", "velocity", "acceleration",
                                      "force", "voltage", "pressure"};
  return (unsigned)q <= RCB_QTY_PRESSURE ? names[q] : "unknown";
}
