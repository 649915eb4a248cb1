/*
 * Rigid disk on one node, DOFs [x, y, rx, ry]: M = diag(m, m, Id, Id),
 * gyroscopic G with Ip coupling the two tilts (G[rx][ry] = Ip,
 * G[ry][rx] = -Ip), so that M q'' + Omega G q' + ... holds with the rotor
 * spinning at +Omega about +z (same sign as ROSS's DiskElement).
 */
#include <string.h>

#include "core/rcb_internal.h"

void rcb_disk_element(double m, double Id, double Ip, double Md[16], double Gd[16]) {
  memset(Md, 0, 16 * sizeof *Md);
  memset(Gd, 0, 16 * sizeof *Gd);
  Md[0 + 4 * 0] = m;
  Md[1 + 4 * 1] = m;
  Md[2 + 4 * 2] = Id;
  Md[3 + 4 * 3] = Id;
  Gd[2 + 4 * 3] = Ip;
  Gd[3 + 4 * 2] = -Ip;
}
