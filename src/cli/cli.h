/* The `hunting` command-line tool: shared option handling and output helpers (no physics here). */
#ifndef HM_CLI_H
#define HM_CLI_H

#include <stdio.h>

#include "hunting_monitor/bogie.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/system.h"

/* One option of a command: --name takes a value unless is_flag. */
typedef struct {
  const char *name;
  const char *arg;  /* value placeholder in help, NULL for a flag */
  const char *help;
} cli_option;

#define CLI_MAX_ARGS 32

/* Parsed command line of one command: option names and values as given. */
typedef struct {
  int count;
  const char *names[CLI_MAX_ARGS];
  const char *values[CLI_MAX_ARGS]; /* NULL for flags */
  const char *positional;           /* at most one positional argument */
} cli_args;

/* Parse argv (argv[0] is the command's name) against the options with getopt_long: --name VALUE, --name=VALUE,
 * unambiguous prefixes, "--" before positional arguments. Prints the error to stderr and returns nonzero on a bad
 * command line. Reorders argv (non-options last). */
int cli_parse(const char *command, int argc, char **argv, const cli_option *opts, int allow_positional,
              cli_args *out);
int cli_has(const cli_args *a, const char *name);
const char *cli_value(const cli_args *a, const char *name);
/* Number option: returns 0 and sets *out (or leaves it if absent); nonzero with a message if malformed. */
int cli_number(const cli_args *a, const char *name, double *out);
/* Comma-separated list of exactly n numbers. */
int cli_number_list(const cli_args *a, const char *name, double *out, int n);

/* The vehicle: --config FILE or the built-in default, then --kx/--ky [MN/m] and --conicity (lambda(0)). */
int cli_vehicle(const cli_args *a, hm_vehicle *veh, char *name);
/* lambda(0) of the vehicle after overrides. */
double cli_conicity0(const hm_vehicle *veh);
/* The model --config describes (none: the wheelset); 1 after printing the config's error. */
int cli_model_kind(const cli_args *a, hm_model_kind *kind);
/* A bogie or car of --config (kind) with --kx, --ky, --conicity applied to its wheelsets, validated, as a system and
 * with its frame (bogie) or carbody (car) held; filled in place (its systems point into it: do not copy it). 1 after
 * printing why not. */
typedef struct {
  hm_model_kind kind;
  hm_vehicle wheelset;   /* the wheelsets' parameters (after the overrides) */
  hm_car params;         /* all of them (a bogie's in params.bogie; the car's default carbody for a bogie) */
  hm_bogie_model bogie, bogie_held;
  hm_car_model car, car_held;
  hm_system sys, held;
  const char *held_name; /* the JSON key of the held variant's critical speed */
} cli_model;
int cli_vehicle_model(const cli_args *a, hm_model_kind kind, cli_model *out);
/* out's model of kind from car's parameters (its systems point into out: keep out in place); the models' status. */
hm_status cli_model_init(hm_model_kind kind, const hm_car *car, cli_model *out);

void cli_print_help(FILE *f, const char *command, const char *usage, const char *summary, const cli_option *opts);


/* A small streaming JSON writer: keys are NULL inside arrays. Numbers in their shortest form that reads back as
 * the same double (round trip); a non-finite number is written as null (JSON has no NaN); keys and strings escaped.
 * Nesting deeper than JW_MAX_DEPTH is an error (jw_ok). */
enum { JW_MAX_DEPTH = 64 };
typedef struct {
  FILE *f;
  int depth;
  int error;                    /* nesting too deep or unbalanced */
  int count[JW_MAX_DEPTH + 1];  /* items written at each depth */
} json_writer;
/* 1 if the document written so far is well formed. */
int jw_ok(const json_writer *w);

void jw_init(json_writer *w, FILE *f);
void jw_object(json_writer *w, const char *key);
void jw_array(json_writer *w, const char *key);
void jw_end_object(json_writer *w);
void jw_end_array(json_writer *w);
void jw_number(json_writer *w, const char *key, double value);
void jw_int(json_writer *w, const char *key, long value);
void jw_string(json_writer *w, const char *key, const char *value);
void jw_bool(json_writer *w, const char *key, int value);
/* An array of n numbers; the eigenvalues as [[re, im], ...]. */
void jw_numbers(json_writer *w, const char *key, const double *x, size_t n);
void jw_eigenvalues(json_writer *w, const char *key, const double re[4], const double im[4]);
/* A spectrum's eigenvalues as [re, im] pairs. */
void jw_spectrum(json_writer *w, const char *key, const hm_system_spectrum *s);
/* Ends the document with a newline. */
void jw_finish(json_writer *w);

/*
 * Read a CSV file with a header line and ncols numeric columns ('#' comment lines and blank lines skipped).
 * header[k] receives the k-th column name (trimmed, up to 63 characters); *data (malloc'd, row-major
 * n x ncols) and *n the rows. Prints "hunting: FILE:LINE: reason" and returns nonzero on any error (missing
 * file, wrong column count, a value that is not a number, or not finite unless allow_nonfinite: recorded
 * sensor data may hold nan or inf, which the online code must see as it would live).
 */
int cli_read_csv(const char *path, int ncols, char header[][64], double **data, size_t *n, int allow_nonfinite);

/* Two columns in millimetres with the header "first,second" (e.g. y_mm,delta_r_mm) into *m_data (malloc'd, 2 n + 1
 * doubles, in metres: the first column, then the second from m_data + n) and *n. Prints "hunting COMMAND: FILE: the
 * header must be ..." (or cli_read_csv's message) and returns nonzero on any error. */
int cli_read_mm_columns(const char *command, const char *path, const char *first, const char *second, double **m_data,
                        size_t *n);

/* The same format read a row at a time (constant memory, for recordings of any length). */
typedef struct {
  FILE *f;
  const char *path;
  int ncols, allow_nonfinite;
  size_t lineno;
  char header[16][64];
} cli_csv;
/* Open and read the header; nonzero (message printed) on failure. ncols 1..16. */
int cli_csv_open(cli_csv *c, const char *path, int ncols, int allow_nonfinite);
/* The next row into row[ncols]: 1, or 0 at the end, or -1 on an error (message printed). */
int cli_csv_next(cli_csv *c, double *row);
void cli_csv_close(cli_csv *c);

/* Commands implemented in cmd_bifurcation.c */
extern const cli_option hopf_opts[], cycles_opts[], hopf_curve_opts[], lpc_curve_opts[];
int cmd_hopf(const cli_args *a);
int cmd_cycles(const cli_args *a);
int cmd_hopf_curve(const cli_args *a);
int cmd_lpc_curve(const cli_args *a);
extern const cli_option tables_opts[], table_lookup_opts[];
int cmd_tables(const cli_args *a);
int cmd_table_lookup(const cli_args *a);
extern const cli_option fit_conicity_opts[], estimate_opts[];
int cmd_estimate(const cli_args *a);
int cmd_fit_conicity(const cli_args *a);
extern const cli_option equivalent_conicity_opts[], delta_r_opts[];
int cmd_delta_r(const cli_args *a);
int cmd_equivalent_conicity(const cli_args *a);
int cli_fail_status(const char *what, hm_status st);
int cli_speed_option(const cli_args *a, double *v_kmh);

#define CLI_VEHICLE_OPTIONS                                                                                  \
  {"config", "FILE", "vehicle config YAML (default: built-in CRH380 defaults = config/crh380_default.yaml)"}, \
      {"kx", "MN/m", "primary longitudinal stiffness Kx (overrides the config)"},                            \
      {"ky", "MN/m", "primary lateral stiffness Ky (overrides the config)"},                                 \
      {"conicity", "L", "equivalent conicity at y = 0 (shifts the constant term of lambda(y))"},            \
      {"help", NULL, "show this help"}

#endif
