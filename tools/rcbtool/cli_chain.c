/* --sensor and --swap (issue #33, item 5): corrections of the measurement
 * chain carried into a fit or a diagnosis, so that a sensor found at fault
 * in one round is read through its correction in the next. The library does
 * the work (rcb_fit_set_sensor, rcb_fit_swap_sensors, rcb_diag_set_sensor,
 * rcb_diag_swap_sensors); this file only reads the options.
 *   --sensor RESP:KEY=V[,KEY=V][,RESP2:KEY=V...]  KEY: gain (-), phase (rad),
 *                                                 sign (-1 or 1)
 *   --swap A,B[,C,D...]                           pairs of swapped probes
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

void cli_chain_free(cli_chain *ch) {
  free(ch->buf);
  free(ch->sens);
  free(ch->swap);
  memset(ch, 0, sizeof *ch);
}

static int number(const cli_args *a, const char *key, const char *s, double *out) {
  char *end;
  errno = 0;
  *out = strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !isfinite(*out))
    return cli_usage(a->cmd, "option --sensor: %s=%s is not a finite number", key, s);
  return 0;
}

/* One KEY=V of sensor e ("seen" holds the keys given: 1 gain, 2 phase, 4 sign). */
static int sensor_key(const cli_args *a, char *item, cli_sensor_edit *e, unsigned *seen) {
  static const char *const keys[] = {"gain", "phase", "sign"};
  char *eq = strchr(item, '=');
  double v;
  unsigned k;
  int rc;
  if (!eq)
    return cli_usage(a->cmd, "option --sensor: '%s' for sensor %s: expected KEY=VALUE with "
                     "KEY gain, phase (rad) or sign (e.g. DB.y:gain=0.8,phase=0)",
                     item, e->response);
  *eq = '\0';
  for (k = 0; k < 3 && strcmp(item, keys[k]) != 0; k++) continue;
  if (k == 3)
    return cli_usage(a->cmd, "option --sensor: unknown key '%s' for sensor %s; expected gain, "
                     "phase (rad) or sign", item, e->response);
  if (*seen & (1u << k))
    return cli_usage(a->cmd, "option --sensor: %s given twice for sensor %s", item,
                     e->response);
  *seen |= 1u << k;
  if ((rc = number(a, item, eq + 1, &v))) return rc;
  if (k == 0 && v == 0.0)
    return cli_usage(a->cmd, "option --sensor: gain=0 for sensor %s: expected a nonzero gain",
                     e->response);
  if (k == 2 && v != 1.0 && v != -1.0)
    return cli_usage(a->cmd, "option --sensor: sign=%s for sensor %s: expected -1 or 1",
                     eq + 1, e->response);
  if (k == 1) e->phase = v;
  else e->gain *= v;
  return 0;
}

static int parse_sensors(const cli_args *a, cli_chain *ch, char *list) {
  size_t n = 1, i;
  unsigned seen = 0;
  char *p, *next;
  int rc;
  for (p = list; *p; p++) n += (*p == ',');
  if (!(ch->sens = calloc(n, sizeof *ch->sens))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (p = list; p; p = next) {
    char *colon;
    if ((next = strchr(p, ','))) *next++ = '\0';
    if ((colon = strchr(p, ':'))) { /* a new sensor: RESP:KEY=V */
      cli_sensor_edit *e = &ch->sens[ch->nsens];
      *colon = '\0';
      if (!*p)
        return cli_usage(a->cmd, "option --sensor: empty sensor name; expected "
                         "RESP:KEY=V[,KEY=V] (e.g. DB.y:gain=0.8 or DB.y:sign=-1)");
      for (i = 0; i < ch->nsens; i++)
        if (ch->sens[i].response && strcmp(ch->sens[i].response, p) == 0)
          return cli_usage(a->cmd, "option --sensor: sensor %s given twice", p);
      e->response = p, e->gain = 1.0, e->phase = 0.0;
      ch->nsens++, seen = 0;
      p = colon + 1;
    } else if (!ch->nsens) {
      return cli_usage(a->cmd, "option --sensor: '%s': expected RESP:KEY=V[,KEY=V] (e.g. "
                       "DB.y:gain=0.8,phase=0 or DB.y:sign=-1)", p);
    }
    if ((rc = sensor_key(a, p, &ch->sens[ch->nsens - 1], &seen))) return rc;
  }
  return 0;
}

static int parse_swaps(const cli_args *a, cli_chain *ch, char *list) {
  size_t n = 1, i;
  char *p, *next;
  for (p = list; *p; p++) n += (*p == ',');
  if (n % 2)
    return cli_usage(a->cmd, "option --swap expects pairs of sensors A,B[,C,D...] (e.g. "
                     "DB.x,DB.y), got %zu name%s", n, n == 1 ? "" : "s");
  if (!(ch->swap = calloc(n, sizeof *ch->swap))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (p = list, i = 0; p; p = next, i++) {
    if ((next = strchr(p, ','))) *next++ = '\0';
    if (!*p) return cli_usage(a->cmd, "option --swap has an empty sensor name");
    ch->swap[i] = p;
    if (i % 2 && strcmp(ch->swap[i - 1], p) == 0)
      return cli_usage(a->cmd, "option --swap: %s with itself; expected two different sensors",
                       p);
  }
  ch->nswap = n / 2;
  return 0;
}

int cli_chain_parse(const cli_args *a, cli_chain *ch) {
  const char *s = cli_opt_value(a, "--sensor"), *w = cli_opt_value(a, "--swap");
  size_t ls = s ? strlen(s) + 1 : 0, lw = w ? strlen(w) + 1 : 0;
  int rc;
  memset(ch, 0, sizeof *ch);
  if (!s && !w) return 0;
  if (!(ch->buf = malloc(ls + lw))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  if (s && (memcpy(ch->buf, s, ls), (rc = parse_sensors(a, ch, ch->buf)))) return rc;
  if (w && (memcpy(ch->buf + ls, w, lw), (rc = parse_swaps(a, ch, ch->buf + ls)))) return rc;
  return 0;
}

int cli_chain_fit(const cli_args *a, const cli_chain *ch, rcb_fit *f) {
  rcb_status st = RCB_OK;
  size_t k;
  for (k = 0; !st && k < ch->nsens; k++)
    st = rcb_fit_set_sensor(f, ch->sens[k].response, ch->sens[k].gain, ch->sens[k].phase);
  for (k = 0; !st && k < ch->nswap; k++)
    st = rcb_fit_swap_sensors(f, ch->swap[2 * k], ch->swap[2 * k + 1]);
  if (st)
    return cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_INPUT : cli_status_exit(st), "%s: %s", a->cmd,
                    cli_msg(rcb_fit_errmsg(f), st));
  return 0;
}

int cli_chain_diag(const cli_args *a, const cli_chain *ch, rcb_diag *d) {
  rcb_status st = RCB_OK;
  size_t k;
  for (k = 0; !st && k < ch->nsens; k++)
    st = rcb_diag_set_sensor(d, ch->sens[k].response, ch->sens[k].gain, ch->sens[k].phase);
  for (k = 0; !st && k < ch->nswap; k++)
    st = rcb_diag_swap_sensors(d, ch->swap[2 * k], ch->swap[2 * k + 1]);
  if (st)
    return cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_INPUT : cli_status_exit(st), "%s: %s", a->cmd,
                    cli_msg(rcb_diag_errmsg(d), st));
  return 0;
}
