/* sweep.h: design-of-experiments runs of a compiled model over its run-time
 * parameters: the design (full factorial, Latin hypercube, one at a time),
 * the job list run by GNU parallel (locally or over ssh) or a Slurm job
 * array, and the merge of the runs' results into one CSV. */
#ifndef MBCC_SWEEP_H
#define MBCC_SWEEP_H

#define SWEEP_MAX_VARS 16
#define SWEEP_MAX_METRICS 64
#define SWEEP_MAX_RUNS 1000000

typedef struct {
  char name[128];
  int nvalue;      /* a list (given, or lo:hi:n spaced), or 0 for a range */
  double *values;
  double lo, hi;   /* a range lo:hi, sampled by the design (lhs) */
  int logspace;    /* lo:hi:n:log */
} sweep_var;

typedef enum { SWEEP_FULL, SWEEP_LHS, SWEEP_OAT } sweep_design_kind;

typedef struct {
  sweep_var var[SWEEP_MAX_VARS];
  int nvar;
  sweep_design_kind design;
  int samples;                 /* lhs: the number of runs */
  unsigned long long seed;     /* lhs */
  const char *metric[SWEEP_MAX_METRICS]; /* COLUMN:STAT; none: max and min of every column */
  int nmetric;
} sweep_plan;

/* NAME=v1,v2,... | NAME=lo:hi:n[:log] | NAME=lo:hi; 0, or 2 after an error on stderr */
int sweep_parse_vary(const char *arg, sweep_var *v);
/* the design's runs: *table holds nrun rows of nvar values (malloc'd);
 * baseline[v] is the nominal value of variable v (one at a time), or NAN
 * (then the middle of its list or range).  0, or 2 after an error. */
int sweep_design(const sweep_plan *p, const double *baseline, double **table, int *nrun);
/* DIR/design.csv and DIR/jobs.txt (one shell command per run: the simulator
 * with --set NAME=VALUE per variable and the fixed arguments), DIR/runs/.
 * Paths are made absolute, so that the jobs run from any directory (and on
 * other machines that share the file system). */
int sweep_write_jobs(const char *dir, const char *exe, const sweep_plan *p, const double *table,
                     int nrun, char *const fixed_args[]);
/* run DIR/jobs.txt with GNU parallel (-j jobs, 0: one per core; sshlogin may
 * be NULL), with progress on stderr unless quiet */
int sweep_run_parallel(const char *dir, int nrun, int jobs, const char *sshlogin, int quiet);
/* a Slurm job-array script running line $SLURM_ARRAY_TASK_ID of DIR/jobs.txt */
int sweep_write_slurm(const char *dir, const char *script, const char *model_name, int nrun,
                      int jobs);
/* DIR/design.csv and the runs' CSVs into one CSV: run, the variables,
 * status, then the metrics.  Returns 0 when every run succeeded, 1 when
 * some failed (listed on stderr and marked in the CSV), 2 on an error. */
int sweep_merge(const char *dir, const sweep_plan *p, const char *out_csv, int quiet);

void sweep_plan_free(sweep_plan *p);

#endif
