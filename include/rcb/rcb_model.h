/**
 * @file rcb_model.h
 * @brief Building a rotor-coupling-bearing model: from an INI file, an INI
 * string, or element by element.
 *
 * A model holds materials, shafts (ordered segments of Timoshenko elements),
 * rigid disks, linear bearings to ground, couplings between shafts,
 * unbalances and named measurement stations. Positions are absolute axial
 * coordinates z (m) along the machine; every station must fall on a node
 * (a segment end or an element boundary).
 *
 * Life cycle: rcb_model_create -> rcb_model_load_* or rcb_model_add_* ->
 * rcb_model_finalize (done by the loaders) -> analyses -> rcb_model_destroy.
 * After finalize the model is read-only for the analyses; rcb_model_set_param
 * may still change numeric values (not the mesh). A structural variant of a
 * model is made on a copy: rcb_model_clone (unfinalized) -> edits
 * (rcb_model_set_coupling_model, rcb_model_set_pedestal,
 * rcb_model_add_disk_at, rcb_model_set_bearing_coefs, any rcb_model_add_*)
 * -> rcb_model_finalize -> rcb_model_set_param.
 */
#ifndef RCB_MODEL_H
#define RCB_MODEL_H

#include "rcb/rcb_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Longest name (materials, shafts, stations...) including the NUL. */
#define RCB_NAME_MAX 48

typedef struct rcb_model rcb_model;

/** @brief Create an empty model. @param alloc allocator hooks, NULL for malloc. */
RCB_API rcb_status rcb_model_create(rcb_model **out, const rcb_allocator *alloc);
/** @brief Free a model and everything it owns (NULL is a no-op). */
RCB_API void rcb_model_destroy(rcb_model *m);
/** @brief Message of the last error on this model ("" if none). */
RCB_API const char *rcb_model_errmsg(const rcb_model *m);

/**
 * @brief Load an INI model file and finalize the model.
 * Errors name the file, line, section, key, what is wrong and what is expected.
 */
RCB_API rcb_status rcb_model_load_file(rcb_model *m, const char *path);
/**
 * @brief Load a model from INI text held in memory (no file system needed).
 * @param source_name name used in error messages (e.g. "<firmware>").
 */
RCB_API rcb_status rcb_model_load_string(rcb_model *m, const char *text,
                                         const char *source_name);

/* ---- element-by-element construction (before finalize) ---- */

/** @param density kg/m^3 @param young Pa @param poisson - */
RCB_API rcb_status rcb_model_add_material(rcb_model *m, const char *name, double density,
                                          double young, double poisson);
/**
 * @brief A shaft: starts at axial position z_start (m), built of segments.
 * @param shear_factor Timoshenko shear coefficient kappa (-), e.g. 0.9.
 */
RCB_API rcb_status rcb_model_add_shaft(rcb_model *m, const char *name, const char *material,
                                       double z_start, double shear_factor);
/**
 * @brief Proportional damping of a shaft's elements: C = qz_m M + qz_k K.
 * @param qz_m mass-proportional factor, 1/s @param qz_k stiffness-proportional factor, s
 */
RCB_API rcb_status rcb_model_set_shaft_damping(rcb_model *m, const char *shaft, double qz_m,
                                               double qz_k);
/**
 * @brief Append a uniform segment to a shaft.
 * @param length m @param outer_d outer diameter, m @param inner_d bore, m (0 = solid)
 * @param n_elements number of equal elements (>= 1)
 */
RCB_API rcb_status rcb_model_add_segment(rcb_model *m, const char *shaft, double length,
                                         double outer_d, double inner_d, int n_elements);
/**
 * @brief Rigid disk at (shaft, z).
 * @param mass kg @param Id diametral inertia, kg m^2 @param Ip polar inertia, kg m^2
 */
RCB_API rcb_status rcb_model_add_disk(rcb_model *m, const char *name, const char *shaft,
                                      double z, double mass, double Id, double Ip);
/**
 * @brief Mass and inertias of a uniform annular disk (also used for coupling hubs).
 * @param density kg/m^3 @param outer_d m @param inner_d m @param width axial, m
 * @param mass kg @param Id kg m^2 (about a diameter through the centre) @param Ip kg m^2
 */
RCB_API rcb_status rcb_disk_from_geometry(double density, double outer_d, double inner_d,
                                          double width, double *mass, double *Id, double *Ip);

/** @brief Linear bearing coefficients: N/m and N s/m, force = -K q - C q'. */
typedef struct rcb_bearing_coefs {
  double kxx, kxy, kyx, kyy; /**< N/m */
  double cxx, cxy, cyx, cyy; /**< N s/m */
} rcb_bearing_coefs;

/** @brief Constant linear bearing to ground at (shaft, z). */
RCB_API rcb_status rcb_model_add_bearing(rcb_model *m, const char *name, const char *shaft,
                                         double z, const rcb_bearing_coefs *c);
/**
 * @brief Speed-dependent bearing: coefficients tabulated against rotor speed,
 * linearly interpolated, held constant outside the table.
 * @param n number of rows (>= 1) @param speeds rad/s, strictly increasing
 */
RCB_API rcb_status rcb_model_add_bearing_table(rcb_model *m, const char *name,
                                               const char *shaft, double z, size_t n,
                                               const double *speeds,
                                               const rcb_bearing_coefs *c);

/**
 * @brief Flexible support under a bearing: a pedestal mass on springs and
 * dampers to ground. The bearing's coefficients then join the shaft node to
 * the pedestal (station "BEARING.ped", directions x and y) instead of ground.
 */
typedef struct rcb_pedestal {
  double mass;     /**< kg, moving in x and y (>= 0) */
  double kxx, kyy; /**< pedestal to ground, N/m (>= 0) */
  double cxx, cyy; /**< pedestal to ground, N s/m (>= 0) */
} rcb_pedestal;

/**
 * @brief Put bearing @p bearing (already added) on a pedestal, before
 * finalize. All zero (or @p p NULL) removes it: the bearing goes to ground.
 * INI keys pedestal_mass, pedestal_kxx, pedestal_kyy, pedestal_cxx,
 * pedestal_cyy; parameters bearing.B.pedestal_mass, ... (see below).
 */
RCB_API rcb_status rcb_model_set_pedestal(rcb_model *m, const char *bearing,
                                          const rcb_pedestal *p);

/** @brief The five coupling models of Tapia & Cavalca (paper section 3). */
typedef enum rcb_coupling_model {
  RCB_COUPLING_KRAMER_1 = 0,         /**< translations tied (DOF elimination) */
  RCB_COUPLING_KRAMER_2 = 1,         /**< translations tied, plus kr, cr */
  RCB_COUPLING_NELSON_CRANDALL_1 = 2, /**< kt, kr */
  RCB_COUPLING_NELSON_CRANDALL_2 = 3, /**< kt, kr, ct, cr */
  RCB_COUPLING_RIGID = 4             /**< all four DOFs tied */
} rcb_coupling_model;

/** @brief Name used in INI files ("kramer_1", ...), NULL if out of range. */
RCB_API const char *rcb_coupling_model_name(rcb_coupling_model t);
/** @brief Parse an INI name; RCB_ERR_NOT_FOUND if unknown. */
RCB_API rcb_status rcb_coupling_model_parse(const char *name, rcb_coupling_model *t);

/**
 * @brief Coupling parameters. Values a model does not use must be 0.
 * Hub inertia: one rigid disk at each of the two coupling stations (a, b).
 */
typedef struct rcb_coupling_params {
  double kt; /**< translational stiffness, N/m */
  double kr; /**< rotational stiffness, N m/rad */
  double ct; /**< translational damping, N s/m */
  double cr; /**< rotational damping, N m s/rad */
  double mass[2]; /**< hub mass at station a, b: kg */
  double Id[2];   /**< hub diametral inertia at a, b: kg m^2 */
  double Ip[2];   /**< hub polar inertia at a, b: kg m^2 */
} rcb_coupling_params;

/**
 * @brief Hub inertia from the paper's Table 1 description: an annulus of
 * equivalent density and thickness, split in two equal halves, one per
 * coupling station. Writes mass[], Id[], Ip[] of @p p.
 * @param density kg/m^3 @param r_inner m @param r_outer m @param thickness whole coupling, m
 */
RCB_API rcb_status rcb_coupling_hubs_from_geometry(double density, double r_inner,
                                                   double r_outer, double thickness,
                                                   rcb_coupling_params *p);

/**
 * @brief Coupling joining station a (shaft_a, z_a) and station b (shaft_b, z_b).
 * Station names "NAME.SHAFT_A" and "NAME.SHAFT_B" are created, and "NAME"
 * alone means station a.
 */
RCB_API rcb_status rcb_model_add_coupling(rcb_model *m, const char *name,
                                          rcb_coupling_model type, const char *shaft_a,
                                          double z_a, const char *shaft_b, double z_b,
                                          const rcb_coupling_params *p);
/**
 * @brief Unbalance at (shaft, z).
 * @param amount kg m @param phase rad, from +x towards +y (direction of rotation)
 */
RCB_API rcb_status rcb_model_add_unbalance(rcb_model *m, const char *name, const char *shaft,
                                           double z, double amount, double phase);
/** @brief A named measurement station (probe position) at (shaft, z). */
RCB_API rcb_status rcb_model_add_station(rcb_model *m, const char *name, const char *shaft,
                                         double z);
/**
 * @brief Map a UFF (universal file) node number to a station name ("DA",
 * "C.B", "#12"), so measurement files written with the test's own node
 * numbers read without a command-line map. Checked by finalize.
 */
RCB_API rcb_status rcb_model_add_uff_node(rcb_model *m, long node, const char *station);
/** @brief Number of UFF node map entries. */
RCB_API size_t rcb_model_uff_node_count(const rcb_model *m);
/** @brief UFF map entry i: node number and station name (owned by the model). */
RCB_API rcb_status rcb_model_uff_node(const rcb_model *m, size_t i, long *node,
                                      const char **station);

/**
 * @brief State the rotor speed (rad/s, >= 0) of the measurements this model
 * is compared with, for files that leave it out (INI: [test] rpm). Used by
 * rcbtool compare, fit and diagnose when neither --rpm nor the file gives it.
 * @return RCB_ERR_ARG unless finite and >= 0
 */
RCB_API rcb_status rcb_model_set_test_speed(rcb_model *m, double speed);
/** @brief The test speed (rad/s) in *speed; RCB_ERR_NOT_FOUND when none is stated. */
RCB_API rcb_status rcb_model_get_test_speed(const rcb_model *m, double *speed);

/** @brief Build the mesh and the DOF map, check consistency. */
RCB_API rcb_status rcb_model_finalize(rcb_model *m);

/* ---- editing a copy: clone, edit, finalize, set parameters ---- */

/**
 * @brief Deep copy of a model, with its own allocator hooks.
 *
 * The copy holds every item of @p src (materials, shafts and segments,
 * disks, bearings with their tables and pedestals, couplings with their
 * hubs, unbalances, stations, the UFF map, the speed factor) and nothing of
 * what finalize derives from them: it is NOT finalized, whatever the state of
 * @p src, so the rcb_model_add_* calls and the edits below apply to it, and
 * it must go through rcb_model_finalize before any query or analysis.
 * Finalizing an unedited copy gives the same nodes, DOF numbers and matrices
 * as the source (warnings are rebuilt, without the INI file:line prefix).
 * @p src is only read; the two models share nothing.
 * @param out the copy (NULL on failure) @param alloc its allocator, NULL for malloc
 * @return RCB_OK, RCB_ERR_ARG, RCB_ERR_NOMEM (nothing is left allocated)
 */
RCB_API rcb_status rcb_model_clone(rcb_model **out, const rcb_model *src,
                                   const rcb_allocator *alloc);
/**
 * @brief Change the model of coupling @p coupling, before finalize.
 * Of kt, kr, ct, cr, those the new model uses keep their values and the
 * others become 0 (as the INI format holds them); hubs are unchanged. Set
 * the new model's values with rcb_model_set_param (before or after finalize).
 */
RCB_API rcb_status rcb_model_set_coupling_model(rcb_model *m, const char *coupling,
                                                rcb_coupling_model type);
/**
 * @brief Replace the coefficients of bearing @p bearing, before finalize: a
 * constant bearing (n = 1, @p speeds may be NULL) or a table against speed
 * as rcb_model_add_bearing_table. Adds any property the bearing lacked
 * (cross-coupling kxy, kyx, anisotropy kxx != kyy, damping, cross damping);
 * a tabulated bearing made constant has fittable coefficients
 * (bearing.B.kxx, ...). Its pedestal, if any, is kept.
 * @param n rows (>= 1) @param speeds rad/s, strictly increasing
 */
RCB_API rcb_status rcb_model_set_bearing_coefs(rcb_model *m, const char *bearing, size_t n,
                                               const double *speeds,
                                               const rcb_bearing_coefs *c);
/**
 * @brief Rigid disk (or a point mass: Id = Ip = 0) at a station, before
 * finalize: @p station is the name of a disk, bearing, coupling ("C" is
 * station a, "C.SHAFT" either one), unbalance or station, or "#N" for node N
 * of the mesh finalize builds (as rcb_model_find_dof numbers them: 0-based
 * along the shafts in definition order). Otherwise as rcb_model_add_disk.
 * @param mass kg @param Id kg m^2 @param Ip kg m^2
 */
RCB_API rcb_status rcb_model_add_disk_at(rcb_model *m, const char *name, const char *station,
                                         double mass, double Id, double Ip);

/* ---- queries (after finalize) ---- */

/**
 * @brief Warnings found by rcb_model_finalize: values that are valid but
 * implausible for a machine in SI units, most often a unit slip (mm where m
 * is meant, g/cm^3, MPa or GPa where Pa is meant), and shafts that no chain
 * of couplings joins (separate rotors). A warning never stops the load; show
 * them to the user (rcbtool check prints them on stderr). Checked: shaft
 * outer diameters outside 1 mm to 5 m, shaft lengths outside 1 mm to 100 m,
 * densities outside 100 to 30000 kg/m^3, Young's moduli outside 1e8 to 1e13
 * Pa, disks heavier than 1e6 kg. The list is made by finalize and kept as is
 * by rcb_model_set_param. Texts start "KIND 'NAME': " (after "FILE:LINE: "
 * when the model came from an INI file).
 * @return number of warnings (0 before finalize)
 */
RCB_API size_t rcb_model_warning_count(const rcb_model *m);
/** @brief Warning i (0-based), owned by the model; NULL when i is out of range. */
RCB_API const char *rcb_model_warning(const rcb_model *m, size_t i);

/** @brief Number of nodes (4 DOFs each before coupling constraints). */
RCB_API size_t rcb_model_node_count(const rcb_model *m);
/** @brief Number of independent DOFs (matrix size) after constraint elimination. */
RCB_API size_t rcb_model_dof_count(const rcb_model *m);
/** @brief Number of shaft elements. */
RCB_API size_t rcb_model_element_count(const rcb_model *m);

/** @brief What is known about a node. */
typedef struct rcb_node_info {
  const char *shaft; /**< owning shaft name */
  double z;          /**< axial position, m */
  long dof[4];       /**< matrix row of x, y, rot_x, rot_y (shared when tied) */
} rcb_node_info;
RCB_API rcb_status rcb_model_node_info(const rcb_model *m, size_t node, rcb_node_info *out);

/** @brief What is known about a shaft element (after finalize). */
typedef struct rcb_element_info {
  const char *shaft;   /**< owning shaft name */
  size_t index;        /**< k of its parameters shaft.SHAFT.e<k>.*: from 1 in z order */
  size_t node0, node1; /**< its end nodes (node1 = node0 + 1) */
  double z0, z1;       /**< axial range, m */
  double outer_d, inner_d; /**< m */
  double stiffness;    /**< factor on E and G (1: as the material states) */
  double mass;         /**< factor on the density (1: as the material states) */
} rcb_element_info;
/**
 * @brief Shaft element e (0-based over the whole model, shaft by shaft in
 * definition order, z order within a shaft; < rcb_model_element_count()).
 * @return RCB_ERR_STATE before finalize, RCB_ERR_NOT_FOUND when out of range
 */
RCB_API rcb_status rcb_model_element_info(const rcb_model *m, size_t e, rcb_element_info *out);

/** @brief Kind of a named station. */
typedef enum rcb_station_kind {
  RCB_STATION_DISK = 0,
  RCB_STATION_BEARING = 1,
  RCB_STATION_COUPLING = 2,
  RCB_STATION_UNBALANCE = 3,
  RCB_STATION_PROBE = 4,
  RCB_STATION_PEDESTAL = 5 /**< "BEARING.ped": x, y only; its node is virtual
                                (>= rcb_model_node_count) */
} rcb_station_kind;

/** @brief Named stations, in definition order. */
RCB_API size_t rcb_model_station_count(const rcb_model *m);
typedef struct rcb_station_info {
  const char *name;
  rcb_station_kind kind;
  size_t node;
} rcb_station_info;
RCB_API rcb_status rcb_model_station_info(const rcb_model *m, size_t i, rcb_station_info *out);

/**
 * @brief Resolve a channel spec to a DOF: "STATION.DIR", where DIR is x, y,
 * rx or ry, and STATION is a station name or "#N" for node N (0-based).
 * Examples: "DA.x", "C.B.y", "B2.ry", "#11.x".
 */
RCB_API rcb_status rcb_model_find_dof(const rcb_model *m, const char *spec, rcb_dof *out);
/** @brief Matrix row of a DOF (after constraint elimination). */
RCB_API rcb_status rcb_model_dof_index(const rcb_model *m, rcb_dof dof, size_t *index);

/**
 * @brief Global matrices at rotor speed @p speed (rad/s; it selects the
 * coefficients of speed-dependent bearings). Each output is n x n column-major,
 * n = rcb_model_dof_count(); any pointer may be NULL.
 * M kg, C N s/m (shaft proportional damping, bearings, couplings), G (multiplied
 * by Omega in the equation of motion; it includes speed.factor), K N/m.
 * Pedestals of bearings add two DOFs each (rcb_model_find_dof "B2.ped.x").
 */
RCB_API rcb_status rcb_model_matrices(const rcb_model *m, double speed, double *M, double *C,
                                      double *G, double *K);

/**
 * @brief Unbalance force phasors at rotor speed @p speed (rad/s): F (length n)
 * such that f(t) = Re(F e^{i Omega t}): F_x = me Omega^2 e^{i phase},
 * F_y = -i F_x.
 */
RCB_API rcb_status rcb_model_unbalance_force(const rcb_model *m, double speed,
                                             rcb_complex *F);


/* ---- parameters by name (identification, issue #3) ---- */

/**
 * Every numeric value that can be fitted has a name "KIND.ITEM.KEY", with the
 * keys of the INI format:
 *  - coupling.C.kt | kr | ct | cr (those its model uses), coupling.C.hub_mass,
 *    hub_Id, hub_Ip (both stations together)
 *  - bearing.B2.kxx ... cyy (constant bearings; tabulated ones are not fittable)
 *  - bearing.B2.pedestal_mass | pedestal_kxx | pedestal_kyy | pedestal_cxx |
 *    pedestal_cyy (bearings on a pedestal), and the views pedestal_k,
 *    pedestal_c setting x and y together
 *  - speed.factor: real rotor speed / stated speed in the gyroscopic and bearing
 *    terms of FRFs, modes and Campbell diagrams (1 = as stated; > 0). The
 *    unbalance response ignores it: there the speed is the measured
 *    once-per-revolution frequency. INI: [model] speed_factor.
 *  - disk.DA.mass | Id | Ip
 *  - shaft.A.damping_mass | damping_stiffness
 *  - shaft.A.stiffness | mass: factors (neutral 1, > 0) on the E and G, and
 *    on the density, of every element of shaft A, on top of the element
 *    factors below: a section or material along the whole shaft other than
 *    stated. INI: [shaft] stiffness_factor | mass_factor (written when not 1).
 *  - shaft.A.e<k>.stiffness | mass: factors (neutral 1, > 0) on element k's
 *    E and G (its whole stiffness matrix, bending and shear) and on its
 *    density (translational and rotary inertia, gyroscopic matrix): a local
 *    loss of stiffness such as a crack, wear or a loose shrink fit. k counts
 *    shaft A's elements from 1 in z order (rcb_model_element_info gives each
 *    element's z range; `rcbtool check` lists them). Not enumerated by
 *    rcb_model_param_count; INI: [shaft] element_stiffness | element_mass =
 *    k factor [k factor ...] (the writer lists those that are not 1).
 *  - shaft.A.e<a>-<b>.stiffness | mass (a <= b): the same factor on elements
 *    a to b together, a section or material change along a span of the
 *    shaft; setting it sets each element's factor, getting it gives element
 *    a's. A view (the model stores the elements' factors; the INI lists
 *    them), as pedestal_k is of a pedestal's x and y.
 *  - material.steel.density | young
 *  - unbalance.UA.amount (kg m) | phase (rad)
 * All of them enter M, C, G, K (and the unbalance force) affinely, which the
 * analytic sensitivities rely on. Units are those of the INI keys (SI; phase in rad).
 */
RCB_API rcb_status rcb_model_get_param(const rcb_model *m, const char *name, double *value);
/**
 * @brief Change a parameter of a finalized (or not yet finalized) model. The
 * mesh is unchanged; analysis objects made before must be refreshed
 * (rcb_frf_refresh). Values are checked as the builder checks them.
 */
RCB_API rcb_status rcb_model_set_param(rcb_model *m, const char *name, double value);
/** @brief Number of fittable parameters of the model. */
RCB_API size_t rcb_model_param_count(const rcb_model *m);
/** @brief Name of fittable parameter i (0-based) into buf. */
RCB_API rcb_status rcb_model_param_name(const rcb_model *m, size_t i, char *buf, size_t size);

/**
 * @brief The model as INI text that rcb_model_load_string reads back to the
 * same matrices (values printed with 17 significant digits). Two-call sizing:
 * with buf NULL or too small, *needed gets the size including the NUL and the
 * call returns RCB_ERR_WORKSPACE (RCB_OK when it fits).
 */
RCB_API rcb_status rcb_model_write_ini(const rcb_model *m, char *buf, size_t size,
                                       size_t *needed);

#ifdef __cplusplus
}
#endif

#endif /* RCB_MODEL_H */
