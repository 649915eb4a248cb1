/* rcbtool: loading the model file and resolving channel lists. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int cli_load_model(const cli_args *a, rcb_model **out) {
  rcb_model *m = NULL;
  rcb_status st;
  char *text = NULL;
  int from_stdin = strcmp(a->model, "-") == 0;
  *out = NULL;
  if (from_stdin) {
    size_t len;
    if (!(text = cli_read_stdin(&len))) return CLI_EXIT_INPUT;
    if (strlen(text) != len) {
      free(text);
      return cli_fail(CLI_EXIT_INPUT, "model from standard input: a NUL byte in the text; "
                      "expected an INI model");
    }
  } else {
    /* A clear message for the commonest mistake, before the parser sees it. */
    FILE *probe = fopen(a->model, "r");
    if (!probe) /* out of memory (fopen's buffer) is exit 4, as everywhere */
      return cli_fail(errno == ENOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT,
                      "cannot open model file '%s': %s", a->model, strerror(errno));
    fclose(probe);
    cli_plan_input(a->model, "model");
  }
  st = rcb_model_create(&m, NULL);
  if (st) {
    free(text);
    return cli_fail(CLI_EXIT_NUMERIC, "cannot create a model: %s", rcb_status_str(st));
  }
  st = from_stdin ? rcb_model_load_string(m, text, "<stdin>") : rcb_model_load_file(m, a->model);
  free(text);
  if (st) {
    const char *msg = rcb_model_errmsg(m);
    cli_fail(CLI_EXIT_INPUT, "%s", msg && *msg ? msg : rcb_status_str(st));
    if (!msg || !strstr(msg, a->model))
      (void)cli_fail(CLI_EXIT_INPUT, "(while loading model file '%s': %s)", a->model,
                     rcb_status_str(st));
    rcb_model_destroy(m);
    return st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT;
  }
  *out = m;
  return 0;
}

void cli_channels_free(cli_channels *ch) {
  free(ch->buf);
  free(ch->names);
  free(ch->dofs);
  memset(ch, 0, sizeof *ch);
}

/* Split @p ch->buf at commas into ch->names; empty items are a usage error. */
static int split_list(const cli_args *a, const char *opt, cli_channels *ch) {
  size_t n = 1, k = 0;
  char *p;
  for (p = ch->buf; *p; p++) n += (*p == ',');
  ch->names = malloc(n * sizeof *ch->names);
  ch->dofs = malloc(n * sizeof *ch->dofs);
  if (!ch->names || !ch->dofs) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  p = ch->buf;
  for (;;) {
    char *comma = strchr(p, ',');
    if (comma) *comma = '\0';
    if (*p == '\0')
      return cli_usage(a->cmd,
                       "option %s has an empty channel name; expected STATION.DIR[,...] "
                       "(e.g. DA.x,C.A.y)",
                       opt);
    ch->names[k++] = p;
    if (!comma) break;
    p = comma + 1;
  }
  ch->n = k;
  return 0;
}

int cli_channels_parse(const cli_args *a, rcb_model *m, const char *opt, cli_channels *ch) {
  const char *list = cli_opt_value(a, opt);
  size_t i;
  int rc;
  memset(ch, 0, sizeof *ch);
  if (!list) return cli_usage(a->cmd, "option %s is required (STATION.DIR[,...])", opt);
  ch->buf = malloc(strlen(list) + 1);
  if (!ch->buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(ch->buf, list);
  if ((rc = split_list(a, opt, ch))) return rc;
  for (i = 0; i < ch->n; i++) {
    rcb_status st = rcb_model_find_dof(m, ch->names[i], &ch->dofs[i]);
    if (st) {
      const char *msg = rcb_model_errmsg(m);
      return cli_usage(a->cmd, "option %s: %s", opt, msg && *msg ? msg : rcb_status_str(st));
    }
  }
  return 0;
}
