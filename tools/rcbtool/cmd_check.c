/* rcbtool check: load and validate a model, print the node/DOF and station tables. */
#include "cli.h"

const char cli_help_check[] =
    "usage: rcbtool check MODEL.ini [--json] [-o FILE]\n"
    "\n"
    "Load and validate MODEL.ini (errors name file:line and exit 3), then print\n"
    "the node table (node, shaft, z in m, matrix rows of the x, y, rot_x, rot_y\n"
    "DOFs; tied DOFs share a row) and the station table (name, kind, node, z in m).\n"
    "Station names are what the channel options of frf and unbalance accept,\n"
    "as STATION.DIR with DIR one of x, y, rx, ry (or #N.DIR for node N).\n"
    "Then the element table: each shaft element's parameters\n"
    "shaft.SHAFT.e<k>.stiffness and shaft.SHAFT.e<k>.mass (factors on its E and G,\n"
    "and on its density; neutral 1), k counted from 1 in z order along the shaft,\n"
    "with its end nodes, z range in m, diameters in m and current factors.\n"
    "\n"
    "CSV: a '# summary' line, the node table, a blank line, the station table,\n"
    "a blank line, the element table.\n"
    "JSON: {\"model\", \"n_nodes\", \"n_elements\", \"ndof\", \"nodes\": [{\"node\",\n"
    "\"shaft\", \"z\", \"dof\": [4]}], \"stations\": [{\"name\", \"kind\", \"node\", \"z\"}],\n"
    "\"elements\": [{\"shaft\", \"k\", \"param\", \"node0\", \"node1\", \"z0\", \"z1\",\n"
    "\"outer_d\", \"inner_d\", \"stiffness\", \"mass\"}]} (param: \"shaft.SHAFT.e<k>\")\n";

static const char *kind_name(rcb_station_kind k) {
  switch (k) {
    case RCB_STATION_DISK:
      return "disk";
    case RCB_STATION_BEARING:
      return "bearing";
    case RCB_STATION_COUPLING:
      return "coupling";
    case RCB_STATION_UNBALANCE:
      return "unbalance";
    case RCB_STATION_PEDESTAL:
      return "pedestal";
    default:
      return "station";
  }
}

static double node_z(const rcb_model *m, size_t node) {
  rcb_node_info ni;
  return rcb_model_node_info(m, node, &ni) == RCB_OK ? ni.z : 0.0;
}

static void write_csv(FILE *fp, const rcb_model *m, const char *path) {
  size_t i, nn = rcb_model_node_count(m), ns = rcb_model_station_count(m);
  fputs("# ", fp);
  cli_put_text(fp, path); /* a file name reaches the terminal escaped (cli_text.c) */
  fprintf(fp, ": %zu nodes, %zu elements, %zu DOFs, %zu stations\n", nn,
          rcb_model_element_count(m), rcb_model_dof_count(m), ns);
  fputs("node,shaft,z_m,dof_x,dof_y,dof_rx,dof_ry\n", fp);
  for (i = 0; i < nn; i++) {
    rcb_node_info ni;
    if (rcb_model_node_info(m, i, &ni)) continue;
    fprintf(fp, "%zu,%s,%.10g,%ld,%ld,%ld,%ld\n", i, ni.shaft, ni.z, ni.dof[0], ni.dof[1],
            ni.dof[2], ni.dof[3]);
  }
  fputs("\nstation,kind,node,z_m\n", fp);
  for (i = 0; i < ns; i++) {
    rcb_station_info si;
    if (rcb_model_station_info(m, i, &si)) continue;
    fprintf(fp, "%s,%s,%zu,%.10g\n", si.name, kind_name(si.kind), si.node,
            node_z(m, si.node));
  }
  fputs("\nparam,shaft,k,node0,node1,z0_m,z1_m,outer_d_m,inner_d_m,stiffness,mass\n", fp);
  for (i = 0; i < rcb_model_element_count(m); i++) {
    rcb_element_info ei;
    if (rcb_model_element_info(m, i, &ei)) continue;
    fprintf(fp, "shaft.%s.e%zu,%s,%zu,%zu,%zu,%.10g,%.10g,%.10g,%.10g,%.15g,%.15g\n", ei.shaft,
            ei.index, ei.shaft, ei.index, ei.node0, ei.node1, ei.z0, ei.z1, ei.outer_d,
            ei.inner_d, ei.stiffness, ei.mass);
  }
}

/* The element table: each element's parameter prefix, nodes, z range, factors. */
static void json_elements(FILE *fp, const rcb_model *m) {
  size_t i;
  char pre[2 * RCB_NAME_MAX + 32];
  fputs("[", fp);
  for (i = 0; i < rcb_model_element_count(m); i++) {
    rcb_element_info ei;
    if (rcb_model_element_info(m, i, &ei)) continue;
    fprintf(fp, "%s\n  {\"shaft\": ", i ? "," : "");
    cli_json_str(fp, ei.shaft);
    snprintf(pre, sizeof pre, "shaft.%s.e%zu", ei.shaft, ei.index);
    fprintf(fp, ", \"k\": %zu, \"param\": ", ei.index);
    cli_json_str(fp, pre);
    fprintf(fp, ", \"node0\": %zu, \"node1\": %zu, \"z0\": ", ei.node0, ei.node1);
    cli_json_num(fp, ei.z0);
    fputs(", \"z1\": ", fp);
    cli_json_num(fp, ei.z1);
    fputs(", \"outer_d\": ", fp);
    cli_json_num(fp, ei.outer_d);
    fputs(", \"inner_d\": ", fp);
    cli_json_num(fp, ei.inner_d);
    fputs(", \"stiffness\": ", fp);
    cli_json_num(fp, ei.stiffness);
    fputs(", \"mass\": ", fp);
    cli_json_num(fp, ei.mass);
    fputs("}", fp);
  }
  fputs("]", fp);
}

void cli_json_nodes(FILE *fp, const rcb_model *m) {
  size_t i, nn = rcb_model_node_count(m);
  fputs("[", fp);
  for (i = 0; i < nn; i++) {
    rcb_node_info ni;
    if (rcb_model_node_info(m, i, &ni)) continue;
    fprintf(fp, "%s\n  {\"node\": %zu, \"shaft\": ", i ? "," : "", i);
    cli_json_str(fp, ni.shaft);
    fputs(", \"z\": ", fp);
    cli_json_num(fp, ni.z);
    fprintf(fp, ", \"dof\": [%ld, %ld, %ld, %ld]}", ni.dof[0], ni.dof[1], ni.dof[2],
            ni.dof[3]);
  }
  fputs("]", fp);
}

static void write_json(FILE *fp, const rcb_model *m, const char *path) {
  size_t i, ns = rcb_model_station_count(m);
  fputs("{\"model\": ", fp);
  cli_json_str(fp, path);
  fprintf(fp, ", \"n_nodes\": %zu, \"n_elements\": %zu, \"ndof\": %zu,\n\"nodes\": ",
          rcb_model_node_count(m), rcb_model_element_count(m), rcb_model_dof_count(m));
  cli_json_nodes(fp, m);
  fputs(",\n\"stations\": [", fp);
  for (i = 0; i < ns; i++) {
    rcb_station_info si;
    if (rcb_model_station_info(m, i, &si)) continue;
    fprintf(fp, "%s\n  {\"name\": ", i ? "," : "");
    cli_json_str(fp, si.name);
    fprintf(fp, ", \"kind\": \"%s\", \"node\": %zu, \"z\": ", kind_name(si.kind), si.node);
    cli_json_num(fp, node_z(m, si.node));
    fputs("}", fp);
  }
  fputs("],\n\"elements\": ", fp);
  json_elements(fp, m);
  fputs("}\n", fp);
}

int cmd_check(int argc, char **argv) {
  cli_args a;
  cli_out o;
  rcb_model *m = NULL;
  int rc = cli_parse(argc, argv, NULL, 0, &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_check);
  if ((rc = cli_load_model(&a, &m))) return rc;
  /* implausible values (unit slips) and separate rotors: stderr, exit 0 */
  for (size_t w = 0; w < rcb_model_warning_count(m); w++)
    cli_warn("%s", rcb_model_warning(m, w));
  if (!(rc = cli_out_open(&o, &a))) {
    if (a.json)
      write_json(o.fp, m, a.model);
    else
      write_csv(o.fp, m, a.model);
    rc = cli_out_close(&o);
  }
  rcb_model_destroy(m);
  return rc;
}
