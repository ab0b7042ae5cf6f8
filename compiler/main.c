/* main.c: the mbcc command line: check, compile, run, bench, modes, plot, trade, animate, sweep. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "animate.h"
#include "bounds.h"
#include "build.h"
#include "diag.h"
#include "emit.h"
#include "fe.h"
#include "flex.h"
#include "help.h"
#include "loads_bdf.h"
#include "lower.h"
#include "mb_driver.h"
#include "order.h"
#include "outfile.h"
#include "params.h"
#include "paths.h"
#include "plot.h"
#include "reader.h"
#include "proc.h"
#include "sweep.h"
#include "trade.h"
#include "unit.h"
#include "vec3.h"
#include "version.h"

#ifndef MBCC_GEN_CFLAGS
#define MBCC_GEN_CFLAGS "-O2"
#endif

static void usage(void) { help_usage(stderr); }

typedef struct {
  const char *model, *scene, *outdir, *csv, *plot, *path, *body, *shapes, *modal_out, *loads;
  const char *results_dir; /* --results DIR: where run's CSV, units and plot go */
  int real_float;   /* --real float: single-precision generated code and runtime */
  int embedded;     /* --target embedded: a package for a microcontroller (emit_embedded.c) */
  const char *sim_args[32];
  int nsim;
  int quiet;
  int animate;      /* run --animate: pose outputs added, and the HTML animation written */
  int suggest;      /* modes --suggest: rank the modes by the loads of a rigid pre-run */
  char set_names[64][128];   /* run --set NAME=VALUE: run-time parameters */
  double set_values[64];
  const char *set_args[64];  /* as given, for the simulator */
  int nset;
} options;

static int parse_options(int argc, char **argv, options *o) {
  memset(o, 0, sizeof *o);
  o->path = "generated";
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (a[0] != '-') {
      if (o->model) { fprintf(stderr, "mbcc: error: more than one model given ('%s')\n", a); return 2; }
      o->model = a;
      continue;
    }
    if (!strcmp(a, "--quiet")) { o->quiet = 1; o->sim_args[o->nsim++] = a; continue; }
    if (!strcmp(a, "--animate")) { o->animate = 1; continue; }
    if (!strcmp(a, "--suggest")) { o->suggest = 1; continue; }
    if (!strcmp(a, "--equilibrium")) {
      if (o->nsim + 1 > 30) { fprintf(stderr, "mbcc: error: too many options\n"); return 2; }
      o->sim_args[o->nsim++] = a;
      continue;
    }
    if (!v) { fprintf(stderr, "mbcc: error: option '%s' needs a value\n", a); return 2; }
    i++;
    if (!strcmp(a, "--set")) {
      const char *eq = strchr(v, '=');
      char *end = NULL;
      double value = eq ? strtod(eq + 1, &end) : 0;
      if (!eq || eq == v || end == eq + 1 || *end || !isfinite(value)) {
        fprintf(stderr, "mbcc: error: --set needs NAME=VALUE with a finite number, got '%s'\n", v);
        return 2;
      }
      if (fabs(value) > LIMIT_MAGNITUDE) { /* the reader's bound on a number in the file */
        fprintf(stderr, "mbcc: error: --set %s: %g is beyond the limit %g on the size of a number\n", v, value,
                LIMIT_MAGNITUDE);
        return 2;
      }
      if (o->nset == 64) { fprintf(stderr, "mbcc: error: more than 64 --set options\n"); return 2; }
      snprintf(o->set_names[o->nset], sizeof o->set_names[0], "%.*s", (int)(eq - v), v);
      o->set_values[o->nset] = value;
      o->set_args[o->nset++] = v;
      continue;
    }
    if (!strcmp(a, "--scene")) o->scene = v;
    else if (!strcmp(a, "--body")) o->body = v;
    else if (!strcmp(a, "--shapes")) o->shapes = v;
    else if (!strcmp(a, "--write-modal")) o->modal_out = v;
    else if (!strcmp(a, "--loads")) o->loads = v;
    else if (!strcmp(a, "-o")) { o->outdir = v; o->csv = v; }
    else if (!strcmp(a, "--plot")) o->plot = v;
    else if (!strcmp(a, "--results")) o->results_dir = v;
    else if (!strcmp(a, "--path")) o->path = v;
    else if (!strcmp(a, "--target")) {
      if (!strcmp(v, "embedded")) o->embedded = 1;
      else if (!strcmp(v, "host")) o->embedded = 0;
      else { fprintf(stderr, "mbcc: error: '--target' must be host or embedded, got '%s'\n", v); return 2; }
    }
    else if (!strcmp(a, "--real")) {
      if (!strcmp(v, "float")) o->real_float = 1;
      else if (!strcmp(v, "double")) o->real_float = 0;
      else { fprintf(stderr, "mbcc: error: '--real' must be float or double, got '%s'\n", v); return 2; }
    }
    else if (!strcmp(a, "--solver") || !strcmp(a, "--integrator") || !strcmp(a, "--end") ||
             !strcmp(a, "--output-step") || !strcmp(a, "--step") || !strcmp(a, "--max-step") || !strcmp(a, "--rtol") ||
             !strcmp(a, "--atol") || !strcmp(a, "--stabilization") || !strcmp(a, "--columns") ||
             !strcmp(a, "--csv") || !strcmp(a, "--reps") || !strcmp(a, "--paths") || !strcmp(a, "--rho-inf") ||
             !strcmp(a, "--max-steps") || !strcmp(a, "--ida-rtol") || !strcmp(a, "--precision")) {
      if (o->nsim + 2 > 30) { fprintf(stderr, "mbcc: error: too many options\n"); return 2; }
      o->sim_args[o->nsim++] = a;
      o->sim_args[o->nsim++] = v;
    } else {
      fprintf(stderr, "mbcc: error: unknown option '%s'\n", a);
      usage();
      return 2;
    }
  }
  if (!o->model) { usage(); return 2; }
  if (strcmp(o->path, "generated") && strcmp(o->path, "generic")) {
    fprintf(stderr, "mbcc: error: unknown path '%s' (expected generated or generic)\n", o->path);
    return 2;
  }
  for (int i = 0; i + 1 < o->nsim; i++)
    if (!strcmp(o->path, "generic") && !strcmp(o->sim_args[i], "--solver") && !strcmp(o->sim_args[i + 1], "ldl")) {
      fprintf(stderr, "mbcc: error: '--solver ldl' is the LDL^T emitted with the generated code; "
              "the generic path has klu or dense\n");
      return 2;
    }
  return 0;
}

/* an output that would replace the model file: refused (exit 2) */
static int refuse_input_as_output(const options *o, const char *out, const char *what) {
  if (!out || !proc_same_file(o->model, out)) return 0;
  fprintf(stderr, "mbcc: error: %s '%s' is the model file itself; choose another name\n", what, out);
  return 2;
}

/* --integrator genalpha or auto on the command line asks for the implicit
 * method as the model's simulation block would: the pattern then carries
 * the force elements' tangents (lower_pattern) */
static void implicit_requested(const options *o, ir_model *ir) {
  for (int i = 0; i + 1 < o->nsim; i++)
    if (!strcmp(o->sim_args[i], "--integrator")) {
      if (!strcmp(o->sim_args[i + 1], "genalpha")) ir->sim.integrator = INTEGRATOR_GENALPHA;
      else if (!strcmp(o->sim_args[i + 1], "auto")) ir->sim.integrator = INTEGRATOR_AUTO;
    }
}

/* the whole pipeline into *u, --animate's pose outputs added to the IR
 * between reading and the rest; 0, or 2 after reporting (u is then freed) */
static int build_read(const options *o, mbc_unit *u, int verbose, int overridden) {
  mb_lapack_context = o->model; /* a LAPACK argument error names the model */
  if (mbc_unit_read(u, o->model, o->scene) || (o->animate && animate_add_pose_outputs(u->ir)) ||
      (implicit_requested(o, u->ir), 0) || ((u->overridden = overridden), mbc_unit_finish(u, verbose))) {
    mbc_unit_free(u);
    return 2;
  }
  u->real_float = o->real_float;
  return 0;
}

static int build(const options *o, mbc_unit *u, int verbose) { return build_read(o, u, verbose, 0); }

/* run --set: each a run-time parameter of the model (read into ir) with a
 * value in its range; 0, or 2 after reporting */
static int check_sets(const options *o, const mbc_unit *u) {
  const ir_model *ir = u->ir;
  for (int i = 0; i < o->nset; i++) {
    char suggest[128];
    int k = params_find(ir, o->set_names[i], suggest, sizeof suggest);
    const ir_param *P = k >= 0 ? &ir->params[k] : NULL;
    if (!P) {
      fprintf(stderr, "mbcc: error: --set %s: the model has no parameter '%s'", o->set_args[i], o->set_names[i]);
      if (suggest[0]) fprintf(stderr, " (did you mean '%s'?)", suggest);
      fputc('\n', stderr);
      return 2;
    }
    if (!P->runtime) {
      diag_error(ir->path, P->loc, "--set %s: parameter '%s' is compile-time (give it 'runtime: true' to "
                 "set it without recompiling, or edit its value)", o->set_args[i], P->name);
      return 2;
    }
    if (!(o->set_values[i] >= P->min && o->set_values[i] <= P->max)) {
      diag_error(ir->path, P->loc, "--set %s: outside the range [%g, %g] of parameter '%s'", o->set_args[i],
                 P->min, P->max, P->name);
      return 2;
    }
  }
  if (!o->nset || u->overridden) return 0;
  /* the values against the rules of the fields they set (a stiffness >= 0 ...) */
  int nrt = 0;
  for (int k = 0; k < ir->nparams; k++) nrt += ir->params[k].runtime;
  double *p = calloc((size_t)nrt + 1, sizeof *p);
  if (p == NULL) return 2;
  char context[1024] = "--set";
  for (int k = 0, j = 0; k < ir->nparams; k++)
    if (ir->params[k].runtime) p[j++] = ir->params[k].value;
  for (int i = 0; i < o->nset; i++) {
    p[params_runtime_index(ir, params_find(ir, o->set_names[i], NULL, 0))] = o->set_values[i];
    size_t used = strlen(context);
    snprintf(context + used, sizeof context - used, " %s", o->set_args[i]);
  }
  int rc = mbc_check_runtime_rules(u, p, context);
  free(p);
  return rc;
}

/* sweep: the run-time parameter vector of each run (the defaults, the
 * shared --set values, the run's varied values) against the fields' rules;
 * 0, or 2 after reporting the first run that breaks one */
static int sweep_check_rules(const mbc_unit *u, const options *o, const sweep_plan *plan, const double *table,
                             int nrun) {
  const ir_model *ir = u->ir;
  int nrt = 0;
  for (int k = 0; k < ir->nparams; k++) nrt += ir->params[k].runtime;
  double *p = calloc((size_t)nrt + 1, sizeof *p);
  if (p == NULL) return 2;
  int rc = 0;
  for (int r = 0; r < nrun && !rc; r++) {
    for (int k = 0, j = 0; k < ir->nparams; k++)
      if (ir->params[k].runtime) p[j++] = ir->params[k].value;
    for (int i = 0; i < o->nset; i++) {
      int k = params_find(ir, o->set_names[i], NULL, 0);
      if (k >= 0 && ir->params[k].runtime) p[params_runtime_index(ir, k)] = o->set_values[i];
    }
    char context[1024];
    int used = snprintf(context, sizeof context, "run %d of the sweep (--vary", r + 1);
    for (int v = 0; v < plan->nvar; v++) {
      int k = params_find(ir, plan->var[v].name, NULL, 0);
      double x = table[(long)r * plan->nvar + v];
      p[params_runtime_index(ir, k)] = x;
      if (used > 0 && (size_t)used < sizeof context)
        used += snprintf(context + used, sizeof context - (size_t)used, " %s=%.17g", plan->var[v].name, x);
    }
    if (used > 0 && (size_t)used < sizeof context) snprintf(context + used, sizeof context - (size_t)used, ")");
    rc = mbc_check_runtime_rules(u, p, context);
  }
  free(p);
  return rc;
}

/* the generic path with --set: the model read again with the values (every
 * field that names them follows, and the model is assembled with them) */
static int build_with_sets(const options *o, mbc_unit *u) {
  if (build(o, u, 0)) return 2;
  if (check_sets(o, u)) { mbc_unit_free(u); return 2; }
  if (!o->nset) return 0;
  mbc_unit_free(u);
  const char *names[64];
  for (int i = 0; i < o->nset; i++) names[i] = o->set_names[i];
  params_set_overrides(names, o->set_values, o->nset);
  int rc = build_read(o, u, 0, 1);
  params_set_overrides(NULL, NULL, 0);
  return rc;
}

/* check --scene: what the scene pruned, and the system's size in the base
 * model and in the scene (the base model built without its report) */
static void check_scene_report(const options *o, const mbc_unit *u) {
  const char *pruned = u->ir->pruned;
  printf("  pruned by the scene%s\n", pruned ? ":" : ": nothing");
  for (const char *line = pruned; line && *line;) {
    const char *end = strchr(line, '\n');
    int length = end ? (int)(end - line) : (int)strlen(line);
    printf("    %.*s\n", length, line);
    line += length + (end != NULL);
  }
  mbc_unit base;
  if (mbc_unit_build(&base, o->model, NULL, 0)) {
    printf("  base model        does not build (see above)\n");
    return;
  }
  const mb_model *b = &base.lowered->m, *s = &u->lowered->m;
  printf("  size              base model -> scene '%s'\n", u->ir->scene);
  printf("    bodies          %d -> %d\n", b->nbody, s->nbody);
  printf("    n               %d -> %d\n", b->n, s->n);
  printf("    nnz(K)          %d -> %d\n", b->nnz, s->nnz);
  if (base.have_plan && u->have_plan) {
    printf("    nnz(L)          %ld -> %ld\n", base.plan.nnzL, u->plan.nnzL);
    printf("    LDL^T flops     %.0f -> %.0f per factorization\n", base.plan.flops, u->plan.flops);
  }
  mbc_unit_free(&base);
}

static int cmd_check(const options *o) {
  mbc_unit u;
  if (build(o, &u, 1)) return 2;
  const ir_model *ir = u.ir;
  const lmodel *L = u.lowered;
  const mb_model *m = &L->m;
  int nrigid = 0, nvirtual = 0;
  for (int b = 0; b < m->nbody; b++) {
    if (m->body[b].kind == MB_BODY_VIRTUAL) nvirtual++;
    else nrigid++;
  }
  printf("model %s%s%s: ok\n", m->name, ir->scene ? ", scene " : "", ir->scene ? ir->scene : "");
  int nflex = 0;
  for (int b = 0; b < m->nbody; b++) nflex += m->body[b].kind == MB_BODY_FLEXIBLE;
  printf("  bodies            %d (%d rigid, %d flexible, %d virtual) + ground\n", m->nbody,
         nrigid - nflex, nflex, nvirtual);
  printf("  coordinates       %d position, %d velocity\n", m->nq, m->nv);
  printf("  joints            %d, drivers %d, forces %d, outputs %d (%d columns)\n", ir->njoints,
         ir->ndrivers, ir->nforces, ir->noutputs, m->ncols);
  printf("  constraint rows   %d (%d redundant removed)\n", m->nc, L->nredundant);
  printf("  degrees of freedom %d\n", L->dof);
  printf("  system dimension  %d (K = [M D^T; D 0])\n", m->n);
  printf("  nnz(K)            %d (%.2f%% dense)\n", m->nnz, m->n ? 100.0 * m->nnz / ((double)m->n * m->n) : 0.0);
  ldl_plan_report(u.have_plan ? &u.plan : NULL, stdout);
  if (L->nvirtual) printf("  virtual bodies    %d inserted for joints on flexible nodes\n", L->nvirtual);
  for (int b = 0; b < m->nbody; b++) {
    if (m->body[b].kind != MB_BODY_FLEXIBLE) continue;
    const fe_modes *fm = &L->modes[b];
    static const char *coupling[] = {"full", "partial", "constant"};
    int rigid = L->ir->bodies[b + 1 < L->ir->nbodies ? b + 1 : 0].flex &&
                L->ir->bodies[b + 1].flex->coupling == COUPLING_RIGID;
    printf("  flexible body '%s': %d nodes, %d modes (coordinates q %d..%d, v %d..%d), coupling %s\n",
           m->body[b].name, fm->nnodes, m->body[b].nm, m->body[b].qadr + 7,
           m->body[b].qadr + 6 + m->body[b].nm, m->body[b].vadr + 6, m->body[b].vadr + 5 + m->body[b].nm,
           rigid ? "rigid (no modes)" : coupling[m->body[b].flex->coupling]);
    printf("    frequencies (Hz):");
    for (int j = 0; j < m->body[b].nm; j++) printf(" %.6g", fm->freq_hz[j]);
    /* the centre of mass, global at t = 0 (undeformed): r + A S0 / m */
    const ir_body *B = &L->ir->bodies[b + 1];
    const mb_flex *fl = m->body[b].flex;
    double A[9], cg[3];
    quaternion_to_matrix(B->orientation, A);
    for (int i = 0; i < 3; i++)
      cg[i] = B->position[i] + (fl->mass > 0 ? (A[3 * i] * fl->S0[0] + A[3 * i + 1] * fl->S0[1] +
                                                A[3 * i + 2] * fl->S0[2]) / fl->mass : 0);
    printf("\n    mass %.6g kg, centre of mass [%.6g, %.6g, %.6g] (global, undeformed)\n", fl->mass,
           fabs(cg[0]) < 1e-12 ? 0 : cg[0], fabs(cg[1]) < 1e-12 ? 0 : cg[1], fabs(cg[2]) < 1e-12 ? 0 : cg[2]);
    printf("    damping ratios:");
    for (int j = 0; j < m->body[b].nm; j++)
      printf(" %.3g", m->body[b].flex->damping[j] / (2 * 2 * MB_PI * fm->freq_hz[j] * sqrt(m->body[b].flex->Mff[j * m->body[b].nm + j])));
    printf("\n");
  }
  if (ir->nparams) printf("  parameters        %d\n", ir->nparams);
  for (int k = 0; k < ir->nparams; k++) {
    const ir_param *P = &ir->params[k];
    printf("    %-16s %.15g%s%s %s", P->name, P->value, P->unit ? " " : "", P->unit ? P->unit : "",
           P->input ? "run-time, input" : P->runtime ? "run-time" : P->uses_runtime ? "compile-time (follows a run-time parameter)" : "compile-time");
    if (P->runtime && (isfinite(P->min) || isfinite(P->max))) printf(" [%g, %g]", P->min, P->max);
    int nused = 0;
    for (int i = 0; i < ir->nuses; i++) {
      if (!expr_names(ir->uses[i].expr, k)) continue;
      printf("%s%d:%d", nused++ ? ", " : ", used at ", diag_loc_in_file(ir->uses[i].loc).line, ir->uses[i].loc.col);
    }
    for (int j = 0; j < ir->nparams; j++)
      if (ir->params[j].expr && expr_names(ir->params[j].expr, k))
        printf("%s'%s'", nused++ ? ", " : ", used at ", ir->params[j].name);
    if (!nused) printf(", unused");
    printf("\n");
  }
  if (ir->scene) check_scene_report(o, &u);
  mbc_unit_free(&u);
  return 0;
}

static void settings_from_ir(const ir_sim *s, mb_settings *set);

static int cmp_int_asc(const void *a, const void *b) {
  int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* a CSV row's fields as numbers into v (at most n); the count */
static int csv_numbers(char *line, double *v, int n) {
  int k = 0;
  for (char *p = line; p && k < n; k++) {
    v[k] = strtod(p, NULL);
    p = strchr(p, ',');
    if (p) p++;
  }
  return k;
}

/* The loads on a flexible body's nodes over a run: the reactions of the
 * joints on its nodes (not distance joints) and the wrenches of the force
 * elements attached to its nodes (point forces and torques, springs,
 * bushings, fields, beams), on the body, in its axes. */
typedef struct {
  int nj, nrows;
  int *joint, *side, *node; /* per load: the joint (or force), the body's side of it, the node */
  int *is_force;            /* per load: 1 when 'joint' is a force element's index */
  double *t;                /* nrows */
  double *f;                /* nrows x nj x 6: Fx Fy Fz Mx My Mz, body axes */
} node_loads;

static void node_loads_free(node_loads *L) {
  free(L->joint); free(L->side); free(L->node); free(L->is_force); free(L->t); free(L->f);
  memset(L, 0, sizeof *L);
}

/* a force element's side 0 reaction acts at its marker 1's point (the field
 * family: bushing, field, beam, superelement), not at its own point */
static int reaction_at_other_point(const ir_force *F) {
  return F->kind == FORCE_BUSHING || F->kind == FORCE_FIELD || F->kind == FORCE_BEAM ||
         F->kind == FORCE_SUPERELEMENT;
}

static void init_output(ir_output *out, const char *prefix, int k) {
  out->body = out->joint = out->driver = out->node = out->mode = out->force = out->rel_node = -1;
  out->chord[0] = out->chord[1] = -1;
  out->component = -1;
  out->scale = 1;
  char name[32];
  snprintf(name, sizeof name, "%s%d", prefix, k);
  out->name = strdup(name);
}

/* Run the model (generic path, its simulation settings and the command's
 * options) with reaction and force outputs for the joints and force
 * elements on body ib's nodes and its orientation; rigid: with the body
 * rigid (coupling: rigid).  0, or 2 after reporting. */
static int run_node_loads(const options *o, int ib, int rigid, node_loads *L) {
  memset(L, 0, sizeof *L);
  mbc_unit u;
  if (mbc_unit_read(&u, o->model, o->scene)) return 2;
  ir_model *ir = u.ir;
  if (rigid) ir->bodies[ib].flex->coupling = COUPLING_RIGID;
  int nj = 0, rc = 2, nmax = ir->njoints + 2 * ir->nforces + 1;
  L->joint = calloc((size_t)nmax, sizeof(int));
  L->side = calloc((size_t)nmax, sizeof(int));
  L->node = calloc((size_t)nmax, sizeof(int));
  L->is_force = calloc((size_t)nmax, sizeof(int));
  /* per load: the first of its lever's position outputs (3 columns each:
     the node, then the element's other point unless on the ground), or -1 */
  int *rel = calloc((size_t)nmax, sizeof(int));
  char dir[] = "/tmp/mbcc-loads-XXXXXX", csv[64] = "";
  FILE *f = NULL;
  double *v = NULL;
  char *line = NULL;
  if (!L->joint || !L->side || !L->node || !L->is_force || !rel) { fprintf(stderr, "mbcc: error: out of memory\n"); goto done; }
  for (int j = 0; j < ir->njoints; j++) {
    const ir_joint *J = &ir->joints[j];
    if (!J->active || J->kind == JOINT_DISTANCE) continue;
    for (int side = 0; side < 2; side++)
      if (J->body[side] == ib && J->node[side] >= 0) {
        L->joint[nj] = j; L->side[nj] = side; L->node[nj] = J->node[side];
        rel[nj++] = -1;
        break;
      }
  }
  int nrel = 0;
  for (int e = 0; e < ir->nforces; e++) {
    const ir_force *F = &ir->forces[e];
    if (!F->active || F->kind == FORCE_TYRE) continue;
    int one = F->kind == FORCE_POINT_FORCE || F->kind == FORCE_POINT_TORQUE;
    for (int side = 0; side < (one ? 1 : 2); side++)
      if (F->body[side] == ib && F->node[side] >= 0) {
        L->joint[nj] = e; L->side[nj] = one ? 1 : side; L->node[nj] = F->node[side]; L->is_force[nj] = 1;
        rel[nj] = -1;
        if (!one && side == 0 && reaction_at_other_point(F)) {
          rel[nj] = nrel;
          nrel += F->body[1] > 0 ? 2 : 1;
        }
        nj++;
      }
  }
  L->nj = nj;
  if (nj == 0) {
    fprintf(stderr, "%s: error: no joint or force element on a node of body '%s' (whose loads are asked for)\n",
            o->model, o->body);
    goto done;
  }
  free_outputs(ir->outputs, ir->noutputs);
  ir->noutputs = nj + 1 + nrel;
  ir->outputs = calloc((size_t)ir->noutputs, sizeof *ir->outputs);
  for (int k = 0; k <= nj && ir->outputs; k++) {
    ir_output *out = &ir->outputs[k];
    init_output(out, k < nj ? "r" : "q", k);
    if (k < nj && L->is_force[k]) { out->kind = OUT_FORCE; out->force = L->joint[k]; }
    else if (k < nj) { out->kind = OUT_REACTION; out->joint = L->joint[k]; }
    else { out->kind = OUT_ORIENTATION; out->body = ib; }
  }
  /* the lever of a side-0 reaction: the positions of the node and of
     marker 1's point (global) */
  for (int k = 0; k < nj && ir->outputs; k++) {
    if (rel[k] < 0) continue;
    const ir_force *F = &ir->forces[L->joint[k]];
    for (int s = 0; s < (F->body[1] > 0 ? 2 : 1); s++) {
      ir_output *out = &ir->outputs[nj + 1 + rel[k] + s];
      init_output(out, s ? "p" : "n", k);
      out->kind = OUT_POSITION;
      out->body = F->body[s];
      out->node = F->node[s];
      out->has_point = true;
      memcpy(out->point, F->point[s], sizeof out->point);
    }
  }
  u.overridden = 1;
  if (!ir->outputs || mbc_unit_finish(&u, 0) || !mkdtemp(dir)) goto done;
  snprintf(csv, sizeof csv, "%s/loads.csv", dir);
  {
    mb_settings set;
    settings_from_ir(&ir->sim, &set);
    char *args[40];
    int na = 0;
    args[na++] = "mbcc-generic";
    args[na++] = "-o";
    args[na++] = csv;
    args[na++] = "--quiet";
    for (int i = 0; i < o->nsim; i++)
      if (strcmp(o->sim_args[i], "--quiet")) args[na++] = (char *)o->sim_args[i];
    args[na] = NULL;
    if (mb_main(na, args, &u.lowered->m, &set, ir->sim.solver == SOLVER_DENSE ? "dense" : "klu")) goto done;
  }
  int ncol = 1 + 6 * nj + 4 + 3 * nrel, cap = 0;
  f = fopen(csv, "r");
  v = calloc((size_t)ncol, sizeof(double));
  line = malloc(1 << 16);
  if (!f || !v || !line || !fgets(line, 1 << 16, f)) {
    fprintf(stderr, "mbcc: error: cannot read the run's results %s\n", csv);
    goto done;
  }
  while (fgets(line, 1 << 16, f)) {
    if (csv_numbers(line, v, ncol) != ncol) continue;
    if (L->nrows == cap) {
      cap = cap ? 2 * cap : 256;
      double *t = realloc(L->t, (size_t)cap * sizeof(double)), *g = realloc(L->f, (size_t)cap * 6 * nj * sizeof(double));
      if (t) L->t = t;
      if (g) L->f = g;
      if (!t || !g) { fprintf(stderr, "mbcc: error: out of memory\n"); goto done; }
    }
    const double *e = v + 1 + 6 * nj; /* Euler parameters: A = (2 e0^2 - 1) I + 2 (e e^T + e0 [e]) */
    double A[9];
    A[0] = 2 * (e[0] * e[0] + e[1] * e[1]) - 1; A[1] = 2 * (e[1] * e[2] - e[0] * e[3]); A[2] = 2 * (e[1] * e[3] + e[0] * e[2]);
    A[3] = 2 * (e[1] * e[2] + e[0] * e[3]); A[4] = 2 * (e[0] * e[0] + e[2] * e[2]) - 1; A[5] = 2 * (e[2] * e[3] - e[0] * e[1]);
    A[6] = 2 * (e[1] * e[3] - e[0] * e[2]); A[7] = 2 * (e[2] * e[3] + e[0] * e[1]); A[8] = 2 * (e[0] * e[0] + e[3] * e[3]) - 1;
    L->t[L->nrows] = v[0];
    for (int k = 0; k < nj; k++) {
      double r[6];
      memcpy(r, v + 1 + 6 * k, sizeof r);
      /* a joint's reaction and a force element's wrench act on its body 1: on
         this body with its side's sign; a field's side-0 reaction acts at
         marker 1's point, d from the node: its moment there adds d x (-F) */
      double sign = L->side[k] == 1 ? 1 : -1;
      if (rel[k] >= 0) {
        const ir_force *F = &ir->forces[L->joint[k]];
        const double *p0 = v + 1 + 6 * nj + 4 + 3 * rel[k], *p1 = F->body[1] > 0 ? p0 + 3 : F->point[1];
        double d[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        r[3] += d[1] * r[2] - d[2] * r[1];
        r[4] += d[2] * r[0] - d[0] * r[2];
        r[5] += d[0] * r[1] - d[1] * r[0];
      }
      double *out = L->f + ((size_t)L->nrows * nj + k) * 6;
      for (int c = 0; c < 3; c++) {
        out[c] = out[3 + c] = 0;
        for (int i = 0; i < 3; i++) { out[c] += sign * A[3 * i + c] * r[i]; out[3 + c] += sign * A[3 * i + c] * r[3 + i]; }
      }
    }
    L->nrows++;
  }
  rc = 0;
done:
  if (f) fclose(f);
  free(v); free(line); free(rel);
  if (csv[0]) unlink(csv);
  if (strcmp(dir, "/tmp/mbcc-loads-XXXXXX")) rmdir(dir);
  mbc_unit_free(&u);
  if (rc) node_loads_free(L);
  return rc;
}

/* mbcc modes --suggest: run the model with the body rigid (coupling: rigid),
 * record the loads of the joints on its nodes, and rank the modes by the
 * static modal amplitude they cause, max_t |x_j^T f(t)| / omega_j^2 (seed 001
 * section 3.4.8): a mode the loads do not excite is not worth its cost,
 * however low its frequency. */
static int suggest_modes(const options *o, int ib, const fe_modes *fm) {
  node_loads L;
  printf("rigid pre-run (body '%s' rigid): ", o->body);
  fflush(stdout);
  if (run_node_loads(o, ib, 1, &L)) { printf("failed\n"); return 2; }
  printf("%d load%s (joints and force elements) on its nodes, %d output times\n", L.nj, L.nj > 1 ? "s" : "", L.nrows);
  int nm = fm->nmodes, nn6 = 6 * fm->nnodes;
  double *amp = calloc((size_t)nm + 1, sizeof(double));
  int *order = calloc((size_t)nm + 1, sizeof(int)), *keep = calloc((size_t)nm + 1, sizeof(int));
  if (!amp || !order || !keep) { free(amp); free(order); free(keep); node_loads_free(&L); return 2; }
  for (int i = 0; i < L.nrows; i++)
    for (int m = 0; m < nm; m++) {
      double lam = pow(6.283185307179586 * fm->freq_hz[m], 2), p = 0;
      for (int k = 0; k < L.nj; k++) {
        const double *x = fm->shapes + (size_t)m * nn6 + 6 * (size_t)L.node[k];
        const double *g = L.f + ((size_t)i * L.nj + k) * 6;
        for (int c = 0; c < 6; c++) p += x[c] * g[c];
      }
      double q = lam > 0 ? fabs(p) / lam : 0;
      if (q > amp[m]) amp[m] = q;
    }
  node_loads_free(&L);
  double total = 0;
  for (int m = 0; m < nm; m++) { order[m] = m; total += amp[m] * amp[m]; }
  if (!(total > 0)) {
    fprintf(stderr, "%s: error: --suggest: the rigid pre-run puts no load on body '%s' (nothing to rank the "
            "modes by: give the model its loads and motion)\n", o->model, o->body);
    free(amp); free(order); free(keep);
    return 2;
  }
  for (int a = 1; a < nm; a++)
    for (int b = a; b > 0 && amp[order[b]] > amp[order[b - 1]]; b--) { int t = order[b]; order[b] = order[b - 1]; order[b - 1] = t; }
  printf("modes ranked by their static amplitude under the pre-run's loads, max_t |x_j^T f| / omega_j^2:\n");
  printf("rank  mode  frequency_hz  amplitude      share\n");
  double cum = 0;
  int nkeep = 0;
  for (int r = 0; r < nm; r++) {
    int m = order[r];
    printf("%4d  %4d  %12.6g  %12.4e  %8.2e\n", r + 1, m + 1, fm->freq_hz[m], amp[m], amp[m] * amp[m] / total);
    /* suggested: the leading modes that carry 99.9 % of the squared amplitude */
    if (cum < 0.999 * total) { keep[nkeep++] = m + 1; cum += amp[m] * amp[m]; }
  }
  qsort(keep, (size_t)nkeep, sizeof(int), cmp_int_asc);
  printf("suggested (99.9 %% of the squared amplitude): modes: {list: [");
  for (int k = 0; k < nkeep; k++) printf("%s%d", k ? ", " : "", keep[k]);
  printf("]}\n");
  free(amp); free(order); free(keep);
  return 0;
}

/* mbcc run --body B --loads FILE.csv: the interface loads of the flexible body over
 * a run of the model (flexible), for fatigue work: per joint or force element on
 * a node, the force and moment on the body at the node, body axes; FILE.bdf
 * (.dat, .nas): the same as Nastran transient loads (loads_bdf.c) */
static int export_loads_bdf(const options *o, int ib, const ir_model *ir, const node_loads *L, out_file *out) {
  const ir_body *B = &ir->bodies[ib];
  const ir_flex *fx = B->flex;
  bdf_load *loads = calloc((size_t)L->nj + 1, sizeof *loads);
  if (!loads) return 2;
  for (int k = 0; k < L->nj; k++) {
    loads[k].grid = fx->node_ids ? fx->node_ids[L->node[k]] : L->node[k];
    loads[k].name = L->is_force[k] ? ir->forces[L->joint[k]].name : ir->joints[L->joint[k]].name;
  }
  /* an imported deck's basic axes are global at t = 0: the body axes turn
     into them by the body's initial orientation; an inline FE model's
     nodes are in body axes already */
  double A0[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (fx->fe_path) {
    const double *e = B->orientation;
    A0[0] = 2 * (e[0] * e[0] + e[1] * e[1]) - 1; A0[1] = 2 * (e[1] * e[2] - e[0] * e[3]); A0[2] = 2 * (e[1] * e[3] + e[0] * e[2]);
    A0[3] = 2 * (e[1] * e[2] + e[0] * e[3]); A0[4] = 2 * (e[0] * e[0] + e[2] * e[2]) - 1; A0[5] = 2 * (e[2] * e[3] - e[0] * e[1]);
    A0[6] = 2 * (e[1] * e[3] - e[0] * e[2]); A0[7] = 2 * (e[2] * e[3] + e[0] * e[1]); A0[8] = 2 * (e[0] * e[0] + e[3] * e[3]) - 1;
  }
  char what[1024];
  snprintf(what, sizeof what, "the loads on the nodes of flexible body '%s' of %s over a run%s%s", o->body, o->model,
           fx->fe_path ? ", FE model " : " (inline FE model: GRID ids are its node numbers, axes its body axes)",
           fx->fe_path ? fx->fe_path : "");
  int n = write_loads_bdf(out->f, what, loads, L->nj, L->nrows, L->t, L->f, A0);
  free(loads);
  if (n < 0) {
    fprintf(stderr, "mbcc: error: cannot write %s\n", o->loads);
    out_file_abort(out);
    return 2;
  }
  if (out_file_commit(out)) return 2;
  printf("wrote %s: %d load channel%s (Nastran TLOAD1/TABLED1, DLOAD 1) of %d load%s on the nodes of body '%s' at %d "
         "times\n", o->loads, n, n == 1 ? "" : "s", L->nj, L->nj > 1 ? "s" : "", o->body, L->nrows);
  return 0;
}

static int ends_with(const char *s, const char *tail) {
  size_t a = strlen(s), b = strlen(tail);
  return a >= b && !strcmp(s + a - b, tail);
}

static int export_loads(const options *o, int ib, const ir_model *ir) {
  node_loads L;
  if (run_node_loads(o, ib, 0, &L)) return 2;
  out_file out;
  if (out_file_open(&out, o->loads)) { node_loads_free(&L); return 2; }
  if (ends_with(o->loads, ".bdf") || ends_with(o->loads, ".dat") || ends_with(o->loads, ".nas")) {
    int st = export_loads_bdf(o, ib, ir, &L, &out);
    node_loads_free(&L);
    return st;
  }
  static const char *const comp[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  fprintf(out.f, "t");
  for (int k = 0; k < L.nj; k++)
    for (int c = 0; c < 6; c++) {
      const ir_flex *fx = ir->bodies[ib].flex; /* nodes by the FE file's ids when it has them */
      long id = fx->node_ids ? fx->node_ids[L.node[k]] : L.node[k];
      fprintf(out.f, ",%s@%ld.%s", L.is_force[k] ? ir->forces[L.joint[k]].name : ir->joints[L.joint[k]].name, id,
              comp[c]);
    }
  fputc('\n', out.f);
  for (int i = 0; i < L.nrows; i++) {
    fprintf(out.f, "%.17g", L.t[i]);
    for (int k = 0; k < 6 * L.nj; k++) fprintf(out.f, ",%.12g", L.f[(size_t)i * 6 * L.nj + k]);
    fputc('\n', out.f);
  }
  int st = out_file_commit(&out) ? 2 : 0;
  if (!st) printf("wrote %s: %d load%s (joints and force elements) on the nodes of body '%s' (N, N m, body axes) at "
                  "%d times\n", o->loads, L.nj, L.nj > 1 ? "s" : "", o->body, L.nrows);
  node_loads_free(&L);
  return st;
}

/* mbcc modes: frequencies and (optionally) mode shapes of one flexible body */
static int cmd_modes(const options *o) {
  if (!o->body) { fprintf(stderr, "mbcc: error: modes needs --body NAME\n"); return 2; }
  mbc_unit u;
  if (mbc_unit_read(&u, o->model, o->scene)) return 2;
  ir_model *ir = u.ir;
  int ib = ir_find_body(ir, o->body);
  if (ib < 0 || ir->bodies[ib].kind != BODY_FLEXIBLE) {
    fprintf(stderr, "%s: error: '%s' is not a flexible body of this model\n", o->model, o->body);
    mbc_unit_free(&u);
    return 2;
  }
  fe_modes fm;
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  int modes_failed = flex_compute_modes(o->model, &ir->bodies[ib], &fm);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  if (modes_failed) {
    mbc_unit_free(&u);
    return 2;
  }
  const ir_flex *fx = ir->bodies[ib].flex;
  int cb = fx->ninterface > 0;
  printf("flexible body '%s': %d nodes, %d modes selected%s\n", o->body, fm.nnodes, fm.nmodes,
         cb ? " (Craig-Bampton: interface constraint modes and fixed-interface normal modes, "
              "orthonormalized)"
            : fx->nresidual > 0 ? " (normal modes and residual attachment modes of the residual_modes nodes)"
            : fx->reference_kind == REFERENCE_FREE ? " (free-free modes in mean axes)"
            : fx->reference_kind == REFERENCE_CHORD ? " (pinned-pinned modes of the chord frame)"
            : " (constrained normal modes)");
  printf("modal analysis: %.3f s (%s)\n", (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec),
         fm.sparse ? "sparse: CHOLMOD and ARPACK shift-invert Lanczos" : fx->modal_file ? "modal data file" : "dense LAPACK");
  printf("mode  frequency_hz\n");
  for (int j = 0; j < fm.nmodes; j++) printf("%4d  %12.6g\n", j + 1, fm.freq_hz[j]);
  printf("%s (%d):", cb ? "fixed-interface normal modes computed, Hz" : "all modes computed, Hz", fm.nall);
  for (int j = 0; j < fm.nall; j++) printf(" %.6g", fm.all_freq_hz[j]);
  printf("\n");
  int st = 0;
  if (o->shapes) {
    out_file out;
    if (out_file_open(&out, o->shapes)) {
      st = 2;
    } else {
      FILE *f = out.f;
      fprintf(f, "node,x,y,z");
      for (int j = 0; j < fm.nmodes; j++)
        fprintf(f, ",m%d_ux,m%d_uy,m%d_uz,m%d_rx,m%d_ry,m%d_rz", j + 1, j + 1, j + 1, j + 1, j + 1, j + 1);
      fputc('\n', f);
      for (int k = 0; k < fm.nnodes; k++) {
        fprintf(f, "%d,%.17g,%.17g,%.17g", k, fm.x[3 * k], fm.x[3 * k + 1], fm.x[3 * k + 2]);
        for (int j = 0; j < fm.nmodes; j++)
          for (int i = 0; i < 6; i++)
            fprintf(f, ",%.17g", fm.shapes[(size_t)j * 6 * (size_t)fm.nnodes + 6 * (size_t)k + (size_t)i]);
        fputc('\n', f);
      }
      if (out_file_commit(&out)) st = 2;
      else printf("wrote %s\n", o->shapes);
    }
  }
  if (!st && o->modal_out) {
    char err[512], desc[600];
    snprintf(desc, sizeof desc, "modes of body '%s' of %s", o->body, o->model);
    if (fe_modes_write(&fm, o->modal_out, desc, err, sizeof err)) {
      fprintf(stderr, "mbcc: error: %s\n", err);
      st = 2;
    } else {
      printf("wrote %s\n", o->modal_out);
    }
  }
  if (!st && o->suggest) st = suggest_modes(o, ib, &fm);
  fe_modes_free(&fm);
  mbc_unit_free(&u);
  return st;
}

/* the embedded package's fixed-step integrator and step: the model's, or
 * --integrator / --step; an adaptive choice (dopri5, auto) becomes RK4 unless
 * the modes are stiff (mb_integrator_auto), then generalized-alpha */
static int embedded_package(const options *o, const mbc_unit *u, const char *dir) {
  const lmodel *L = u->lowered;
  mb_settings set;
  settings_from_ir(&L->ir->sim, &set);
  for (int i = 0; i + 1 < o->nsim; i += 2) {
    const char *a = o->sim_args[i], *v = o->sim_args[i + 1];
    char *end;
    if (!strcmp(a, "--integrator")) {
      if (!strcmp(v, "rk4")) set.integrator = MB_RK4;
      else if (!strcmp(v, "genalpha")) set.integrator = MB_GENALPHA;
      else { fprintf(stderr, "mbcc: error: --target embedded integrates with rk4 or genalpha, not '%s'\n", v); return 2; }
    } else if (!strcmp(a, "--step")) {
      set.step = strtod(v, &end);
      if (*end || !(set.step > 0)) { fprintf(stderr, "mbcc: error: '--step' must be a positive number, got '%s'\n", v); return 2; }
    }
  }
  if (set.integrator == MB_AUTO || set.integrator == MB_DOPRI5) {
    set.integrator = mb_integrator_auto(&L->m, &set, NULL, 0) == MB_GENALPHA ? MB_GENALPHA : MB_RK4;
    if (set.step > set.output_step) set.step = set.output_step;
  }
  int st = emit_embedded(u, dir, set.integrator, set.step);
  if (!st) printf("wrote the embedded package %s/ (%s, step %g s)\n", dir, mb_integrator_name(set.integrator), set.step);
  return st;
}

/* build and emit into -o DIR or generated/<name>; with dir_out (run, bench)
 * always the latter, its name in dir_out.  With up the unit is kept there
 * for the caller to free (also on failure after building).  --target
 * embedded: the package into -o DIR or generated/<name>-embedded. */
static int cmd_compile(const options *o, char *dir_out, size_t n, mbc_unit *up) {
  mbc_unit u;
  if (o->embedded) ldl_set_default_budget(LDL_FLOP_BUDGET_EMBEDDED); /* flash over speed */
  if (build(o, &u, 0)) return 2;
  const char *name = u.lowered->m.name;
  if (o->embedded) {
    char pdir[4096];
    if (o->outdir) snprintf(pdir, sizeof pdir, "%s", o->outdir);
    else snprintf(pdir, sizeof pdir, "generated/%s-embedded", name);
    mkdir("generated", 0777);
    int st = embedded_package(o, &u, pdir);
    if (up) *up = u;
    else mbc_unit_free(&u);
    return st;
  }
  char dir[4096];
  if (o->outdir && !dir_out) snprintf(dir, sizeof dir, "%s", o->outdir);
  else snprintf(dir, sizeof dir, "generated/%s", name);
  mkdir("generated", 0777);
  int st = emit_model(&u, dir);
  if (!st && !dir_out) {
    char **srcs = generated_sources(dir, name);
    int n = 0;
    while (srcs && srcs[n]) n++;
    if (n > 1) /* a large model in several translation units (emit_files.h) */
      printf("wrote %s/%s.h, %d C files (listed in %s/%s.sources) and %s/main.c\n", dir, name, n, dir, name, dir);
    else
      printf("wrote %s/%s.c, %s/%s.h and %s/main.c\n", dir, name, dir, name, dir);
    for (int i = 0; srcs && srcs[i]; i++) free(srcs[i]);
    free(srcs);
  }
  if (dir_out) snprintf(dir_out, n, "%s", dir);
  if (up) *up = u;
  else mbc_unit_free(&u);
  return st;
}

int run_command(char *const argv[]) { return proc_run(argv); }

/* the runtime settings of the model's simulation block */
static void settings_from_ir(const ir_sim *s, mb_settings *set) {
  mb_settings_default(set);
  set->integrator = (int)s->integrator; /* ir_integrator numbers the runtime's */
  set->rho_inf = s->rho_inf;
  set->end_time = s->end_time; set->output_step = s->output_step; set->step = s->step;
  set->rtol = s->rtol; set->atol = s->atol; set->min_step = s->min_step; set->max_step = s->max_step;
  set->stabilization = (int)s->stabilization;
  set->alpha = s->baumgarte_alpha; set->beta = s->baumgarte_beta;
  set->equilibrium = s->equilibrium;
}

/* the simulator's options checked before anything is compiled: the values
 * the simulator would refuse, and options of other commands */
static int check_run_options(const options *o) {
  mb_settings scratch;
  mb_settings_default(&scratch);
  for (int i = 0; i < o->nsim; i++) {
    const char *a = o->sim_args[i], *v = i + 1 < o->nsim ? o->sim_args[i + 1] : "";
    if (!strcmp(a, "--quiet") || !strcmp(a, "--equilibrium")) continue;
    i++;
    if (!strcmp(a, "--columns")) continue;
    if (!strcmp(a, "--precision")) { /* the CSV writer's (driver.c), checked the same way */
      char *end;
      double d = strtod(v, &end);
      if (end == v || *end || !(d >= 1 && d <= 17) || d != (int)d) {
        fprintf(stderr, "mbcc: error: '--precision' needs a number of digits from 1 to 17, got '%s'\n", v);
        return 2;
      }
      continue;
    }
    if (!strcmp(a, "--solver")) {
      if (strcmp(v, "ldl") && strcmp(v, "klu") && strcmp(v, "dense")) {
        fprintf(stderr, "mbcc: error: unknown solver '%s' (expected ldl, klu or dense)\n", v);
        return 2;
      }
      continue;
    }
    int k = mb_settings_option(&scratch, a, v, "mbcc");
    if (k < 0) return 2;
    if (k == 0) {
      fprintf(stderr, "mbcc: error: '%s' is not an option of mbcc run\n", a);
      usage();
      return 2;
    }
  }
  return 0;
}

/* run's CSV without -o: NAME.csv in --results DIR, else in results/ (made
   here: only the last directory) */
static void default_csv(const options *o, const char *name, char *csv, size_t n) {
  const char *dir = o->results_dir ? o->results_dir : "results";
  mkdir(dir, 0777);
  snprintf(csv, n, "%s/%s.csv", dir, name);
}

/* emit the model and compile its simulator generated/NAME/NAME_sim (reused
 * when nothing it is made of changed); its path in exe_final.  The unit is
 * kept in *u for the caller to free; 0, or 2 after reporting (u freed). */
static int build_simulator(const options *o, char *exe_final, size_t n, mbc_unit *u) {
  char dir[4096];
  options o2 = *o;
  o2.outdir = NULL;
  memset(u, 0, sizeof *u);
  int rc = cmd_compile(&o2, dir, sizeof dir, u);
  if (!rc) rc = check_sets(o, u);
  if (rc) { mbc_unit_free(u); return rc; }
  const lmodel *L = u->lowered;
  /* the simulator under a name of this process's own (two runs of one
     model at once must not build over each other), then put in place */
  char exe[8420], src_main[8400];
  snprintf(exe_final, n, "%s/%s_sim", dir, L->m.name);
  snprintf(exe, sizeof exe, "%s.XXXXXX", exe_final);
  snprintf(src_main, sizeof src_main, "%s/main.c", dir);
  int efd = mkstemp(exe);
  if (efd < 0) {
    fprintf(stderr, "mbcc: error: cannot write '%s': %s\n", exe_final, strerror(errno));
    mbc_unit_free(u);
    return 2;
  }
  close(efd);
  proc_cleanup_add(exe);
  int reused = 0;
  rc = compile_generated_into(dir, L->m.name, src_main, exe, exe_final, NULL, o->quiet, o->real_float, &reused);
  /* built under its own name and renamed into place whole, or reused */
  unlink(exe);
  proc_cleanup_remove(exe);
  if (rc) { mbc_unit_free(u); return 2; }
  return 0;
}

/* mbcc run --body B --loads FILE.csv: the run's loads on body B's nodes
 * instead of the model's outputs */
static int cmd_run_loads(const options *o) {
  if (!o->body) {
    fprintf(stderr, "mbcc: error: --loads needs --body NAME (the flexible body whose loads are written)\n");
    return 2;
  }
  mbc_unit u;
  if (mbc_unit_read(&u, o->model, o->scene)) return 2;
  int ib = ir_find_body(u.ir, o->body);
  if (ib < 0 || u.ir->bodies[ib].kind != BODY_FLEXIBLE) {
    fprintf(stderr, "%s: error: '%s' is not a flexible body of this model\n", o->model, o->body);
    mbc_unit_free(&u);
    return 2;
  }
  int st = export_loads(o, ib, u.ir);
  mbc_unit_free(&u);
  return st;
}

static int cmd_run(const options *o) {
  if (o->loads) return cmd_run_loads(o);
  if (check_run_options(o)) return 2;
  mbc_unit u;
  char csv[4096];
  if (o->csv) snprintf(csv, sizeof csv, "%s", o->csv);
  int rc;
  if (!strcmp(o->path, "generic")) {
    /* in-process, without code generation: the generic path */
    options o2 = *o;
    o2.outdir = NULL;
    if (build_with_sets(&o2, &u)) return 2;
    const lmodel *Lg = u.lowered;
    if (!o->csv) default_csv(o, Lg->m.name, csv, sizeof csv);
    const ir_sim *s = &u.ir->sim;
    mb_settings set;
    settings_from_ir(s, &set);
    char *args[40];
    int na = 0;
    args[na++] = "mbcc-generic";
    args[na++] = "-o";
    args[na++] = csv;
    for (int i = 0; i < o->nsim; i++)
      if (strcmp(o->sim_args[i], "--columns")) args[na++] = (char *)o->sim_args[i];
      else i++;
    args[na] = NULL;
    /* the generic path has no emitted LDL^T: a model that asks for ldl (the
       default) runs there with KLU */
    rc = refuse_input_as_output(o, csv, "the results file");
    if (!rc) rc = mb_main(na, args, &Lg->m, &set, s->solver == SOLVER_DENSE ? "dense" : "klu");
  } else {
    char exe_final[8400];
    rc = build_simulator(o, exe_final, sizeof exe_final, &u);
    if (rc) return rc;
    if (!o->csv) default_csv(o, u.lowered->m.name, csv, sizeof csv);
    char *args[40 + 2 * 64];
    int na = 0;
    args[na++] = exe_final;
    args[na++] = "-o";
    args[na++] = csv;
    for (int i = 0; i < o->nset; i++) { /* the simulator sets them: nothing recompiled */
      args[na++] = "--set";
      args[na++] = (char *)o->set_args[i];
    }
    for (int i = 0; i < o->nsim; i++)
      if (strcmp(o->sim_args[i], "--columns")) args[na++] = (char *)o->sim_args[i];
      else i++;
    args[na] = NULL;
    if (refuse_input_as_output(o, csv, "the results file")) rc = 2;
    else rc = run_command(args);
  }
  mbc_unit_free(&u);
  if (rc) return rc;
  if (!o->plot || strcmp(o->plot, "none")) {
    char png[4096];
    if (o->plot) snprintf(png, sizeof png, "%s", o->plot);
    else {
      snprintf(png, sizeof png, "%s", csv);
      char *dot = strrchr(png, '.');
      if (dot && !strcmp(dot, ".csv")) strcpy(dot, ".png");
      else strncat(png, ".png", sizeof png - strlen(png) - 1);
    }
    const char *columns = NULL;
    for (int i = 0; i + 1 < o->nsim; i++)
      if (!strcmp(o->sim_args[i], "--columns")) columns = o->sim_args[i + 1];
    if (refuse_input_as_output(o, png, "the plot")) return 2;
    const char *files[] = {csv};
    if (plot_files(1, files, png, columns, o->quiet)) return 2;
  }
  if (o->animate) { /* the page beside the CSV: results/<model>.html */
    char html[4096];
    animate_page_name(csv, html, sizeof html);
    return animate_write(csv, o->model, o->scene, html, 1, o->quiet);
  }
  return 0;
}

/* DIR/bench_main.c: the model's default settings, then mb_bench_main */
/* mbcc bench: generate, compile a bench executable (with SUNDIALS IDA), run it */
static int cmd_bench(const options *o) {
  char dir[4096];
  mbc_unit u;
  memset(&u, 0, sizeof u);
  options o2 = *o;
  o2.outdir = NULL;
  int rc = cmd_compile(&o2, dir, sizeof dir, &u);
  if (rc) { mbc_unit_free(&u); return rc; }
  const lmodel *L = u.lowered;
  char exe[8400], src_main[8400];
  snprintf(exe, sizeof exe, "%s/%s_bench", dir, L->m.name);
  snprintf(src_main, sizeof src_main, "%s/bench_main.c", dir);
  char *ida_libs[] = {"-lsundials_ida", "-lsundials_nvecserial", "-lsundials_sunlinsolklu",
                      "-lsundials_sunmatrixsparse", NULL};
  rc = emit_template(&u, "bench_main.c.in", src_main);
  if (!rc && o->real_float) {
    fprintf(stderr, "mbcc: error: bench runs double-precision paths only (drop '--real float')\n");
    rc = 2;
  }
  if (!rc) rc = compile_generated(dir, L->m.name, src_main, exe, ida_libs, o->quiet, 0);
  mbc_unit_free(&u);
  if (rc) return rc;
  char *args[40];
  int na = 0;
  args[na++] = exe;
  for (int i = 0; i < o->nsim; i++) args[na++] = (char *)o->sim_args[i];
  args[na] = NULL;
  return run_command(args);
}

/* mbcc plot A.csv [B.csv ...] [-o OUT.png] [--columns a,b+c] [--gnuplot FILE] [--quiet] */
static int cmd_plot(int argc, char **argv) {
  const char *files[64], *png_opt = NULL, *columns = NULL;
  int nfiles = 0, quiet = 0;
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "--quiet")) { quiet = 1; continue; }
    if (a[0] != '-') {
      if (nfiles == 64) { fprintf(stderr, "mbcc: error: more than 64 CSV files\n"); return 2; }
      files[nfiles++] = a;
      continue;
    }
    if (i + 1 >= argc) { fprintf(stderr, "mbcc: error: option '%s' needs a value\n", a); return 2; }
    if (!strcmp(a, "-o")) png_opt = argv[++i];
    else if (!strcmp(a, "--columns")) columns = argv[++i];
    else if (!strcmp(a, "--gnuplot")) plot_keep_script = argv[++i];
    else {
      fprintf(stderr, "mbcc: error: unknown option '%s' (mbcc plot --help)\n", a);
      return 2;
    }
  }
  if (!nfiles) { usage(); return 2; }
  char png[4096];
  if (png_opt) snprintf(png, sizeof png, "%s", png_opt);
  else {
    snprintf(png, sizeof png, "%s", files[0]);
    char *dot = strrchr(png, '.');
    if (dot && !strchr(dot, '/')) strcpy(dot, ".png");
    else strncat(png, ".png", sizeof png - strlen(png) - 1);
  }
  return plot_files(nfiles, files, png, columns, quiet);
}


/* mbcc sweep M.yaml --vary NAME=SPEC ... : compile once, run the design's
 * variants of the run-time parameters with GNU parallel (or write a Slurm
 * job array), merge the results; mbcc sweep --merge DIR merges again */
static int cmd_sweep(int argc, char **argv) {
  sweep_plan p;
  memset(&p, 0, sizeof p);
  p.design = SWEEP_FULL;
  p.seed = 1;
  const char *dir = NULL, *csv = NULL, *sshlogin = NULL, *slurm = NULL, *merge = NULL;
  int jobs = 0, quiet = 0, rc = 2;
  char *rest[80 + 2 * 64], *fixed[64 + 2 * 64];
  int nrest = 0, nfixed = 0;
  rest[nrest++] = argv[0];
  rest[nrest++] = argv[1];
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    int takes = !strcmp(a, "--vary") || !strcmp(a, "--design") || !strcmp(a, "--samples") ||
                !strcmp(a, "--seed") || !strcmp(a, "--metric") || !strcmp(a, "--dir") ||
                !strcmp(a, "--csv") || !strcmp(a, "--jobs") || !strcmp(a, "-j") ||
                !strcmp(a, "--sshlogin") || !strcmp(a, "--slurm") || !strcmp(a, "--merge");
    if (!takes) {
      if (!strcmp(a, "--quiet")) quiet = 1;
      if (nrest >= 78 + 2 * 64) { fprintf(stderr, "mbcc: error: too many options\n"); goto done; }
      rest[nrest++] = argv[i];
      continue;
    }
    if (!v) { fprintf(stderr, "mbcc: error: option '%s' needs a value\n", a); goto done; }
    i++;
    char *end;
    if (!strcmp(a, "--vary")) {
      if (p.nvar == SWEEP_MAX_VARS) { fprintf(stderr, "mbcc: error: at most %d --vary\n", SWEEP_MAX_VARS); goto done; }
      if (sweep_parse_vary(v, &p.var[p.nvar])) { p.nvar++; goto done; }
      for (int k = 0; k < p.nvar; k++)
        if (!strcmp(p.var[k].name, p.var[p.nvar].name)) {
          fprintf(stderr, "mbcc: error: '%s' is varied twice\n", p.var[k].name);
          p.nvar++;
          goto done;
        }
      p.nvar++;
    } else if (!strcmp(a, "--design")) {
      if (!strcmp(v, "full")) p.design = SWEEP_FULL;
      else if (!strcmp(v, "lhs")) p.design = SWEEP_LHS;
      else if (!strcmp(v, "oat")) p.design = SWEEP_OAT;
      else { fprintf(stderr, "mbcc: error: '--design' must be full, lhs or oat, got '%s'\n", v); goto done; }
    } else if (!strcmp(a, "--samples")) {
      long n = strtol(v, &end, 10);
      if (*end || n < 1 || n > SWEEP_MAX_RUNS) {
        fprintf(stderr, "mbcc: error: '--samples' needs a whole number from 1 to %d, got '%s'\n", SWEEP_MAX_RUNS, v);
        goto done;
      }
      p.samples = (int)n;
    } else if (!strcmp(a, "--seed")) {
      p.seed = strtoull(v, &end, 10);
      if (*end || !*v) { fprintf(stderr, "mbcc: error: '--seed' needs a whole number, got '%s'\n", v); goto done; }
    } else if (!strcmp(a, "--metric")) {
      if (p.nmetric == SWEEP_MAX_METRICS) { fprintf(stderr, "mbcc: error: at most %d --metric\n", SWEEP_MAX_METRICS); goto done; }
      p.metric[p.nmetric++] = v;
    } else if (!strcmp(a, "--jobs") || !strcmp(a, "-j")) {
      long n = strtol(v, &end, 10);
      if (*end || n < 1 || n > 4096) { fprintf(stderr, "mbcc: error: '%s' needs a number of jobs from 1 to 4096, got '%s'\n", a, v); goto done; }
      jobs = (int)n;
    } else if (!strcmp(a, "--dir")) dir = v;
    else if (!strcmp(a, "--csv")) csv = v;
    else if (!strcmp(a, "--sshlogin")) sshlogin = v;
    else if (!strcmp(a, "--slurm")) slurm = v;
    else merge = v;
  }
  char csv_default[4200];
  if (merge) {
    if (!csv) { snprintf(csv_default, sizeof csv_default, "%.4000s/sweep.csv", merge); csv = csv_default; }
    rc = sweep_merge(merge, &p, csv, quiet);
    goto done;
  }
  if (!p.nvar) { fprintf(stderr, "mbcc: error: mbcc sweep needs at least one --vary NAME=...\n"); goto done; }
  options o;
  rest[nrest] = NULL;
  if (parse_options(nrest, rest, &o)) goto done;
  if (strcmp(o.path, "generated")) { fprintf(stderr, "mbcc: error: a sweep runs the generated simulator (drop '--path')\n"); goto done; }
  if (o.outdir) { fprintf(stderr, "mbcc: error: a sweep writes its runs to --dir DIR and the merged results to --csv FILE (not -o)\n"); goto done; }
  if (check_run_options(&o)) goto done;
  /* the simulation options of the runs, as mbcc run passes them, and the
     --set values every run shares */
  for (int i = 0; i < o.nset; i++) {
    fixed[nfixed++] = "--set";
    fixed[nfixed++] = (char *)o.set_args[i];
  }
  for (int i = 0; i < o.nsim; i++) {
    if (!strcmp(o.sim_args[i], "--quiet")) continue;
    if (!strcmp(o.sim_args[i], "--columns") || !strcmp(o.sim_args[i], "--precision")) {
      if (!strcmp(o.sim_args[i], "--columns")) { i++; continue; }
    }
    if (nfixed >= 62 + 2 * 64) { fprintf(stderr, "mbcc: error: too many options\n"); goto done; }
    fixed[nfixed++] = (char *)o.sim_args[i];
  }
  fixed[nfixed] = NULL;
  double *table = NULL;
  int nrun = 0;
  double baseline[SWEEP_MAX_VARS], pmin[SWEEP_MAX_VARS], pmax[SWEEP_MAX_VARS];
  for (int k = 0; k < p.nvar; k++) baseline[k] = NAN;
  mbc_unit u;
  char exe[8400];
  if (build_simulator(&o, exe, sizeof exe, &u)) goto done;
  char dir_default[4200];
  if (!dir) {
    mkdir("sweeps", 0777);
    snprintf(dir_default, sizeof dir_default, "sweeps/%.4000s", u.lowered->m.name);
    dir = dir_default;
  }
  char name[256];
  snprintf(name, sizeof name, "%s", u.lowered->m.name);
  /* every varied name a run-time parameter, not also fixed by --set; one
     at a time starts from the parameters' values in the model */
  for (int k = 0; k < p.nvar && rc == 2; k++) {
    char suggest[128];
    int ip = params_find(u.ir, p.var[k].name, suggest, sizeof suggest);
    if (ip < 0) {
      fprintf(stderr, "mbcc: error: --vary %s: the model has no parameter '%s'", p.var[k].name, p.var[k].name);
      if (suggest[0]) fprintf(stderr, " (did you mean '%s'?)", suggest);
      fputc('\n', stderr);
      rc = 3;
    } else if (!u.ir->params[ip].runtime) {
      diag_error(u.ir->path, u.ir->params[ip].loc, "--vary %s: parameter '%s' is compile-time (give it "
                 "'runtime: true' to vary it without recompiling)", p.var[k].name, p.var[k].name);
      rc = 3;
    } else {
      baseline[k] = u.ir->params[ip].value;
      pmin[k] = u.ir->params[ip].min;
      pmax[k] = u.ir->params[ip].max;
      for (int i = 0; i < o.nset; i++)
        if (!strcmp(o.set_names[i], p.var[k].name)) {
          fprintf(stderr, "mbcc: error: '%s' is both varied and set\n", p.var[k].name);
          rc = 3;
        }
    }
  }
  if (rc != 2) { rc = 2; mbc_unit_free(&u); goto done; }
  if (sweep_design(&p, baseline, &table, &nrun)) { mbc_unit_free(&u); goto done; }
  for (int r = 0; r < nrun; r++)
    for (int k = 0; k < p.nvar; k++) {
      double x = table[(long)r * p.nvar + k];
      if (!(x >= pmin[k] && x <= pmax[k])) {
        fprintf(stderr, "mbcc: error: --vary %s: the value %.17g is outside the parameter's range [%g, %g]\n",
                p.var[k].name, x, pmin[k], pmax[k]);
        free(table);
        mbc_unit_free(&u);
        goto done;
      }
    }
  /* every run's values against the rules of the fields they set, before any run */
  if (sweep_check_rules(&u, &o, &p, table, nrun)) {
    free(table);
    mbc_unit_free(&u);
    goto done;
  }
  mbc_unit_free(&u);
  if (sweep_write_jobs(dir, exe, &p, table, nrun, fixed)) { free(table); goto done; }
  free(table);
  if (!quiet) fprintf(stderr, "mbcc sweep: %d runs of %s; jobs in %s/jobs.txt\n", nrun, name, dir);
  if (slurm) {
    rc = sweep_write_slurm(dir, slurm, name, nrun, jobs);
    if (!rc && !quiet)
      fprintf(stderr, "mbcc sweep: wrote the Slurm job array %s: submit it with 'sbatch %s', then merge "
              "with 'mbcc sweep --merge %s'\n", slurm, slurm, dir);
    goto done;
  }
  if (sweep_run_parallel(dir, nrun, jobs, sshlogin, quiet)) goto done;
  if (!csv) { snprintf(csv_default, sizeof csv_default, "%.4000s/sweep.csv", dir); csv = csv_default; }
  rc = sweep_merge(dir, &p, csv, quiet);
done:
  sweep_plan_free(&p);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    usage();
    return 2;
  }
  if (!strcmp(argv[1], "--version")) {
    printf("mbcc %s\n", MBCC_VERSION);
    return 0;
  }
  if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
    if (argc > 2 && !strcmp(argv[2], "--man")) { help_man(stdout); return 0; }
    if (argc > 2 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))) return help_print(stdout, "help");
    if (argc > 2 && help_print(stdout, argv[2])) {
      fprintf(stderr, "mbcc: error: no command '%s' (mbcc help lists them)\n", argv[2]);
      return 2;
    }
    return argc > 2 ? 0 : help_print(stdout, NULL);
  }
  const char *cmd = argv[1];
  /* mbcc CMD --help: that command's help, whatever else is on the line */
  for (int i = 2; i < argc; i++)
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
      if (help_print(stdout, cmd)) break; /* an unknown command: reported below */
      return 0;
    }
  options o;
  if (!strcmp(cmd, "trade")) return cmd_trade(argc, argv);
  if (!strcmp(cmd, "animate")) return cmd_animate(argc, argv);
  if (!strcmp(cmd, "plot")) return cmd_plot(argc, argv);
  if (!strcmp(cmd, "sweep")) return cmd_sweep(argc, argv);
  if (strcmp(cmd, "check") && strcmp(cmd, "compile") && strcmp(cmd, "run") && strcmp(cmd, "modes") &&
      strcmp(cmd, "bench")) {
    fprintf(stderr, "mbcc: error: unknown command '%s'\n", cmd);
    usage();
    return 2;
  }
  if (parse_options(argc, argv, &o)) return 2;
  if (o.nset && strcmp(cmd, "run")) {
    fprintf(stderr, "mbcc: error: --set is an option of mbcc run (and of the generated simulator)\n");
    return 2;
  }
  if (refuse_input_as_output(&o, o.plot, "the plot") || refuse_input_as_output(&o, o.shapes, "the shapes file") ||
      refuse_input_as_output(&o, o.modal_out, "the modal file") ||
      (strcmp(cmd, "compile") && refuse_input_as_output(&o, o.csv, "the output")))
    return 2;
  if (!strcmp(cmd, "check")) return cmd_check(&o);
  if (!strcmp(cmd, "modes")) return cmd_modes(&o);
  if (!strcmp(cmd, "compile")) return cmd_compile(&o, NULL, 0, NULL);
  if (!strcmp(cmd, "bench")) return cmd_bench(&o);
  return cmd_run(&o);
}
