/* emit_embedded.c: mbcc compile --target embedded writes a self-contained
 * package for a microcontroller: the generated model, the freestanding core
 * (runtime/core: kernels, model tables, the fixed-step integrators of
 * mb_step.c), a step API in <model>_api.h/.c whose data block has a size
 * known at compile time, a Makefile for a cross compiler, a Cortex-M start
 * for qemu's mps2-an386 board, an example and a verification main, and a
 * README (templates/embedded/).  Everything is written into DIR.pkg first and
 * moved into DIR at the end: nothing half-written. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "diag.h"
#include "emit.h"
#include "emit_files.h"
#include "lower.h"
#include "params.h"

/* the core sources a package needs, from runtime/core */
static const char *const core_files[] = {
    "mb_types.h", "mb_math.h", "mb_kernels.h", "mb_flex.h", "mb_model.h", "model_generic.c", "mb_step.h",
    "mb_step.c", "elements/mb_field.h", "elements/mb_force_point.h", "elements/mb_spring.h",
    "elements/mb_tyre.h", "elements/mb_superelement.h"};
/* the package's folders (core_files and template_files name files in them) */
static const char *const subdirs[] = {"board", "elements"};
/* templates/embedded/<name>, written as <name> with @MODEL@ / @UMODEL@ filled */
static const char *const template_files[] = {"Makefile", "README.md", "example_main.c", "verify_main.c", "timing_main.c",
                                             "board/startup.c", "board/mps2_an386.ld"};

/* copy src to dst, replacing @MODEL@, @UMODEL@ and @DEFS@ (templates) or nothing */
static int copy_file(const char *src, const char *dst, const char *nm, const char *U, const char *defs) {
  FILE *in = fopen(src, "r");
  if (!in) { diag_error(NULL, (ir_loc){0, 0}, "cannot read '%s' (set MBCC_ROOT?)", src); return 2; }
  FILE *out = fopen(dst, "w");
  if (!out) { fclose(in); diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s'", dst); return 2; }
  char line[2048];
  while (fgets(line, sizeof line, in)) {
    for (char *p = line; *p;) {
      if (nm && !strncmp(p, "@MODEL@", 7)) { fputs(nm, out); p += 7; }
      else if (nm && !strncmp(p, "@UMODEL@", 8)) { fputs(U, out); p += 8; }
      else if (nm && !strncmp(p, "@DEFS@", 6)) { fputs(defs, out); p += 6; }
      else fputc(*p++, out);
    }
  }
  fclose(in);
  int bad = ferror(out);
  if (fclose(out) || bad) { diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s'", dst); return 2; }
  return 0;
}

/* In the package, the model's own <m>_init (the constant entries of K) is
 * renamed <m>_init_constants: <m>_init is the API's.  Whole identifiers only. */
static int rename_model_init(const char *path, const char *nm) {
  FILE *in = fopen(path, "r");
  if (!in) return 2;
  char tmp[4500];
  snprintf(tmp, sizeof tmp, "%s.ren", path);
  FILE *out = fopen(tmp, "w");
  if (!out) { fclose(in); return 2; }
  char from[300];
  snprintf(from, sizeof from, "%s_init", nm);
  size_t n = strlen(from);
  char line[8192];
  while (fgets(line, sizeof line, in)) {
    for (char *p = line; *p;) {
      int starts = p == line || !(isalnum((unsigned char)p[-1]) || p[-1] == '_');
      if (starts && !strncmp(p, from, n) && !(isalnum((unsigned char)p[n]) || p[n] == '_')) {
        fprintf(out, "%s_constants", from);
        p += n;
      } else fputc(*p++, out);
    }
  }
  fclose(in);
  int bad = ferror(out);
  if (fclose(out) || bad || rename(tmp, path)) { remove(tmp); return 2; }
  return 0;
}

static int has_power_law(const lmodel *L) {
  for (int k = 0; k < L->m.nforce_law; k++)
    if (L->force_law[k].kind == MB_LAW_POWER) return 1;
  return 0;
}

/* The package's settings go into its mb_types.h, which every source includes.
 * A float package fixes the precision: no object of it can be built in double
 * by mistake (an ABI mismatch).  A model without power laws compiles their
 * kernel out (mb_spring.h: no powf, no newlib errno and reentrancy data), one
 * without tyres the tyre (mb_tyre.h: no asinf), and mb_step.c keeps only the
 * package's integrator. */
static int has_force_kind(const lmodel *L, mb_force_kind kind) {
  for (int k = 0; k < L->m.nforce; k++)
    if (L->force[k].kind == kind) return 1;
  return 0;
}

static int package_settings(const char *path, const mbc_unit *u, int integrator) {
  FILE *f = fopen(path, "a");
  if (!f) return 2;
  if (u->real_float)
    fputs("\n/* this package is single precision (mbcc --real float): every file computes in float */\n"
          "#ifndef MB_REAL_FLOAT\n#error \"compile this package with -DMB_REAL_FLOAT (its Makefile does)\"\n#endif\n", f);
  if (!has_power_law(u->lowered))
    fputs("\n/* the model has no power-law spring: its kernel (and powf) is left out */\n"
          "#define MB_NO_POWER_LAW 1\n", f);
  if (!has_force_kind(u->lowered, MB_FORCE_TYRE))
    fputs("\n/* the model has no tyre: the element (and asinf) is left out */\n"
          "#define MB_NO_TYRE 1\n", f);
  if (!has_force_kind(u->lowered, MB_FORCE_SUPERELEMENT))
    fputs("\n/* the model has no superelement: its kernel is left out */\n"
          "#define MB_NO_SUPERELEMENT 1\n", f);
  fprintf(f, "\n/* the package steps with one integrator: mb_step.c leaves the other out */\n"
             "#define MB_STEP_INTEGRATOR_ONLY %d\n", integrator == 2 ? 2 : 0);
  return fclose(f) ? 2 : 0;
}

static void c_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    if (*s == '"' || *s == '\\') fputc('\\', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

/* the model's run-time parameters (its parameter vector, as emit.c numbers
 * them) and, among them, its inputs ('input: true'); none when the code
 * folds them (a unit whose IR changed after reading) */
static int param_count(const mbc_unit *u, int inputs_only) {
  int n = 0;
  for (int k = 0; !u->overridden && k < u->ir->nparams; k++)
    n += inputs_only ? u->ir->params[k].input : u->ir->params[k].runtime;
  return n;
}

static void write_api_header(FILE *f, const mbc_unit *u, const char *nm, const char *U, int integrator,
                             double step) {
  const lmodel *L = u->lowered;
  const mb_model *m = &L->m;
  fprintf(f, "/* %s_api.h: generated by mbcc (--target embedded) from %s. Do not edit.\n"
             " * The step API of the model: all state in one %s_data block (no allocation);\n"
             " * see README.md. */\n", nm, L->ir->path, nm);
  fprintf(f, "#ifndef %s_API_H\n#define %s_API_H\n\n#include \"%s.h\"\n#include \"mb_step.h\"\n\n", U, U, nm);
  fprintf(f, "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n");
  fprintf(f, "#define %s_INTEGRATOR %s /* fixed-step integrator */\n", U,
          integrator == 2 ? "MB_STEP_GENALPHA" : "MB_STEP_RK4");
  fprintf(f, "#define %s_STEP %.17g /* suggested step, s (the model's simulation step) */\n", U, step);
  fprintf(f, "#define %s_NINPUT %d  /* inputs (%s_set_input): the model's parameters with 'input: true' */\n", U,
          param_count(u, 1), nm);
  fprintf(f, "#define %s_NPARAM %d  /* run-time parameters, inputs included (their vector is in the data block) */\n",
          U, param_count(u, 0));
  fprintf(f, "#define %s_NOUTPUT %s_NCOLS /* outputs (%s_outputs) */\n", U, U, nm);
  fprintf(f, "#define %s_NBODY %d\n#define %s_NMARKER %d\n", U, m->nbody, U, m->nmarker);
  fprintf(f, "/* bytes of the data block: a compile-time constant */\n");
  fprintf(f, "#define %s_DATA_BYTES MB_STEP_BYTES(%s_NQ, %s_NV, %s_NC, %s_N, %s_NNZ, %s_LDL_WORK, \\\n"
             "    %s_NPARAM, MB_STEP_FRAMES(%s_NBODY, %s_NMARKER), %s_INTEGRATOR == MB_STEP_GENALPHA)\n\n",
          U, U, U, U, U, U, U, U, U, U, U);
  fprintf(f, "/* the data block: declare one (static) per simulated instance; 8-byte aligned */\n"
             "typedef union {\n  unsigned char bytes[%s_DATA_BYTES];\n  long long align_;\n} %s_data;\n\n",
          U, nm);
  fprintf(f, "/* start from the model's initial state (projected onto the constraints); 0 or an mb_status */\n"
             "int %s_init(%s_data *d);\n", nm, nm);
  fprintf(f, "/* advance by dt seconds; 0 or an mb_status (MB_ERR_SINGULAR, MB_ERR_NONFINITE,\n"
             " * MB_ERR_PROJECTION): then call %s_init to restart */\n"
             "int %s_step(%s_data *d, mb_real dt);\n", nm, nm, nm);
  fprintf(f, "/* set input k (0..%s_NINPUT-1, named in %s_input_names) to value from the next\n"
             " * %s_step or %s_outputs on (it holds until set again; %s_init restores the\n"
             " * model's value); MB_ERR_INVALID, and nothing changed, if k is out of range or\n"
             " * the value is not finite or outside the parameter's min..max */\n"
             "int %s_set_input(%s_data *d, int k, mb_real value);\n", U, nm, nm, nm, nm, nm, nm);
  fprintf(f, "/* the %s_NOUTPUT output columns at the current state into y; 0 or an mb_status */\n"
             "int %s_outputs(%s_data *d, mb_real *y);\n", U, nm, nm);
  fprintf(f, "/* the current time, s */\nmb_real %s_time(const %s_data *d);\n", nm, nm);
  fprintf(f, "extern const char *const %s_input_names[%s_NINPUT + 1];\n", nm, U);
  fprintf(f, "extern const char *const %s_output_names[%s_NOUTPUT + 1];\n\n", nm, U);
  fprintf(f, "#ifdef __cplusplus\n}\n#endif\n\n#endif\n");
}

static void write_api_source(FILE *f, const mbc_unit *u, const char *nm, const char *U) {
  const lmodel *L = u->lowered;
  const mb_model *m = &L->m;
  const ir_model *ir = u->ir;
  int nparam = param_count(u, 0);
  fprintf(f, "/* %s_api.c: generated by mbcc (--target embedded) from %s. Do not edit. */\n", nm, L->ir->path);
  fprintf(f, "#include \"%s_api.h\"\n\n", nm);
  fprintf(f, "const char *const %s_input_names[%s_NINPUT + 1] = {", nm, U);
  for (int k = 0, j = 0; nparam && k < ir->nparams; k++)
    if (ir->params[k].input) {
      fputs(j++ ? ", " : "", f);
      c_string(f, ir->params[k].name);
    }
  fputs(param_count(u, 1) ? ", 0};\n" : "0};\n", f);
  /* input k is element input_param[k] of the parameter vector */
  fprintf(f, "static const int input_param[%s_NINPUT + 1] = {", U);
  for (int k = 0; nparam && k < ir->nparams; k++)
    if (ir->params[k].input) fprintf(f, "%d, ", params_runtime_index(ir, k));
  fputs("-1};\n", f);
  fprintf(f, "const char *const %s_output_names[%s_NOUTPUT + 1] = {", nm, U);
  for (int c = 0; c < m->ncols; c++) {
    fputs(c ? ", " : "\n  ", f);
    c_string(f, m->col_name[c]);
  }
  fputs(m->ncols ? ", 0\n};\n\n" : "0};\n\n", f);
  fprintf(f, "static mb_stepper *stepper(%s_data *d) { return (mb_stepper *)(void *)d->bytes; }\n\n", nm);
  if (nparam)
    fprintf(f, "/* this instance's parameter vector (s->u) into the model's force pools, which\n"
               " * all instances share: each API call that evaluates the model sets them first */\n"
               "static mb_stepper *with_params(mb_stepper *s) {\n"
               "  s->m->set_params(s->m, s->u);\n  return s;\n}\n\n");
  else
    fputs("static mb_stepper *with_params(mb_stepper *s) { return s; } /* no run-time parameters */\n\n", f);
  fprintf(f, "int %s_init(%s_data *d) {\n"
             "  mb_step_settings set;\n  mb_stepper *s;\n"
             "  mb_step_defaults(&set);\n  set.integrator = %s_INTEGRATOR;\n", nm, nm, U);
  if (nparam) fprintf(f, "  %s_model.set_params(&%s_model, %s_model.param_value); /* the model's values */\n", nm, nm, nm);
  fprintf(f, "  int st = mb_step_init(&s, d->bytes, sizeof d->bytes, &%s_model, %s_NPARAM,\n"
             "                        MB_STEP_FRAMES(%s_NBODY, %s_NMARKER), &set);\n", nm, U, U, U);
  if (nparam)
    fprintf(f, "  if (s)\n    for (int k = 0; k < %s_NPARAM; k++) s->u[k] = %s_model.param_value[k];\n", U, nm);
  fputs("  return st;\n}\n\n", f);
  fprintf(f, "int %s_step(%s_data *d, mb_real dt) { return mb_step(with_params(stepper(d)), dt); }\n\n", nm, nm);
  fprintf(f, "int %s_set_input(%s_data *d, int k, mb_real value) {\n"
             "  if (k < 0 || k >= %s_NINPUT) return MB_ERR_INVALID;\n", nm, nm, U);
  if (param_count(u, 1))
    fprintf(f, "  int p = input_param[k];\n"
               "  /* a NaN fails both comparisons */\n"
               "  if (!(value >= %s_model.param_min[p] && value <= %s_model.param_max[p])) return MB_ERR_INVALID;\n"
               "  stepper(d)->u[p] = value;\n  return MB_OK;\n}\n\n", nm, nm);
  else
    fputs("  (void)d, (void)value, (void)input_param;\n  return MB_OK;\n}\n\n", f);
  fprintf(f, "int %s_outputs(%s_data *d, mb_real *y) { return mb_step_outputs(with_params(stepper(d)), y); }\n\n",
          nm, nm);
  fprintf(f, "mb_real %s_time(const %s_data *d) { return ((const mb_stepper *)(const void *)d->bytes)->t; }\n",
          nm, nm);
}

static int join(char *out, size_t n, const char *a, const char *b) {
  int k = snprintf(out, n, "%s/%s", a, b);
  return k < 0 || (size_t)k >= n;
}

/* the files emit_model writes beside <m>.c and <m>.h for a model in
 * several translation units (emit_files.h): what <m>.sources lists but
 * <m>.c, the list itself and <m>_parts.h; NULL-terminated, or NULL */
static char **split_files(const char *dir, const char *nm) {
  char **listed = emit_files_read_list(dir, nm);
  int n = 0;
  while (listed && listed[n]) n++;
  char **v = listed ? calloc((size_t)n + 3, sizeof *v) : NULL;
  int k = 0, ok = v != NULL;
  char name[300];
  snprintf(name, sizeof name, "%s.sources", nm);
  if (ok) ok = (v[k++] = strdup(name)) != NULL;
  snprintf(name, sizeof name, "%s_parts.h", nm);
  if (ok) ok = (v[k++] = strdup(name)) != NULL;
  snprintf(name, sizeof name, "%s.c", nm);
  for (int i = 0; ok && i < n; i++) {
    if (!strcmp(listed[i], name)) free(listed[i]);
    else v[k++] = listed[i];
    listed[i] = NULL;
  }
  emit_files_list_free(listed);
  if (!ok) { /* out of memory: the package cannot be complete */
    emit_files_list_free(v);
    return NULL;
  }
  return v;
}

/* remove what a failed write_package left in tmp (only names it writes) */
static void remove_partial(const char *tmp, const char *nm) {
  char path[4400], fn[300];
  char **split = split_files(tmp, nm);
  for (int i = 0; split && split[i]; i++)
    if (!join(path, sizeof path, tmp, split[i])) remove(path);
  emit_files_list_free(split);
  static const char *const suffixes[] = {".c", ".h", "_api.c", "_api.h"};
  for (size_t i = 0; i < 4; i++) {
    snprintf(fn, sizeof fn, "%s%s", nm, suffixes[i]);
    if (!join(path, sizeof path, tmp, fn)) remove(path);
  }
  for (size_t i = 0; i < sizeof core_files / sizeof core_files[0]; i++)
    if (!join(path, sizeof path, tmp, core_files[i])) remove(path);
  for (size_t i = 0; i < sizeof template_files / sizeof template_files[0]; i++)
    if (!join(path, sizeof path, tmp, template_files[i])) remove(path);
  if (!join(path, sizeof path, tmp, "main.c")) remove(path);
  for (size_t i = 0; i < sizeof subdirs / sizeof subdirs[0]; i++)
    if (!join(path, sizeof path, tmp, subdirs[i])) rmdir(path);
  rmdir(tmp);
}

static int write_package(const mbc_unit *u, const char *dir, const char *tmp, int integrator, double step) {
  const lmodel *L = u->lowered;
  const char *nm = L->m.name;
  char U[256], path[4400], src[4400];
  upper(U, nm, sizeof U);
  /* the model itself (writes <m>.c, <m>.h and a hosted main.c, which goes) */
  if (emit_model(u, tmp)) return 2;
  if (join(path, sizeof path, tmp, "main.c")) return 2;
  remove(path);
  for (int k = 0; k < 2; k++) {
    char fn[300];
    snprintf(fn, sizeof fn, k ? "%s.c" : "%s.h", nm);
    if (join(path, sizeof path, tmp, fn) || rename_model_init(path, nm)) {
      diag_error(NULL, (ir_loc){0, 0}, "cannot rewrite '%s'", path);
      return 2;
    }
  }
  for (size_t i = 0; i < sizeof subdirs / sizeof subdirs[0]; i++) {
    if (join(path, sizeof path, tmp, subdirs[i])) return 2;
    if (mkdir(path, 0777) && errno != EEXIST) {
      diag_error(NULL, (ir_loc){0, 0}, "cannot create directory '%s': %s", path, strerror(errno));
      return 2;
    }
  }
  const char *root = emit_root_dir();
  for (size_t i = 0; i < sizeof core_files / sizeof core_files[0]; i++) {
    snprintf(src, sizeof src, "%s/runtime/core/%s", root, core_files[i]);
    if (join(path, sizeof path, tmp, core_files[i]) || copy_file(src, path, NULL, NULL, NULL)) return 2;
    if (!strcmp(core_files[i], "mb_types.h") && package_settings(path, u, integrator)) return 2;
  }
  for (size_t i = 0; i < sizeof template_files / sizeof template_files[0]; i++) {
    snprintf(src, sizeof src, "%s/templates/embedded/%s", root, template_files[i]);
    if (join(path, sizeof path, tmp, template_files[i]) || copy_file(src, path, nm, U, u->real_float ? "-DMB_REAL_FLOAT" : "")) return 2;
  }
  char name[300];
  for (int k = 0; k < 2; k++) {
    snprintf(name, sizeof name, k ? "%s_api.c" : "%s_api.h", nm);
    if (join(path, sizeof path, tmp, name)) return 2;
    FILE *f = fopen(path, "w");
    if (!f) { diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s'", path); return 2; }
    if (k) write_api_source(f, u, nm, U);
    else write_api_header(f, u, nm, U, integrator, step);
    int bad = ferror(f);
    if (fclose(f) || bad) { diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s'", path); return 2; }
  }
  /* move everything into DIR */
  if (mkdir(dir, 0777) && errno != EEXIST) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot create directory '%s': %s", dir, strerror(errno));
    return 2;
  }
  for (size_t i = 0; i < sizeof subdirs / sizeof subdirs[0]; i++) {
    char sub[4400];
    if (join(sub, sizeof sub, dir, subdirs[i])) return 2;
    mkdir(sub, 0777);
  }
  /* the model's files: a large model's other translation units too (the
     package Makefile compiles what <m>.sources lists) */
  char **split = split_files(tmp, nm);
  const char *model_files[4];
  char f0[300], f1[300], f2[300], f3[300];
  snprintf(f0, sizeof f0, "%s.c", nm);
  snprintf(f1, sizeof f1, "%s.h", nm);
  snprintf(f2, sizeof f2, "%s_api.c", nm);
  snprintf(f3, sizeof f3, "%s_api.h", nm);
  model_files[0] = f0; model_files[1] = f1; model_files[2] = f2; model_files[3] = f3;
  size_t ncore = sizeof core_files / sizeof core_files[0], ntpl = sizeof template_files / sizeof template_files[0];
  size_t nsplit = 0;
  while (split && split[nsplit]) nsplit++;
  for (size_t i = 0; i < 4 + ncore + ntpl + nsplit; i++) {
    const char *fn = i < 4 ? model_files[i] : i < 4 + ncore ? core_files[i - 4]
                   : i < 4 + ncore + ntpl ? template_files[i - 4 - ncore] : split[i - 4 - ncore - ntpl];
    char to[4400];
    if (join(path, sizeof path, tmp, fn) || join(to, sizeof to, dir, fn)) return 2;
    if (rename(path, to)) {
      diag_error(NULL, (ir_loc){0, 0}, "cannot move '%s' to '%s': %s", path, to, strerror(errno));
      emit_files_list_free(split);
      return 2;
    }
  }
  emit_files_list_free(split);
  for (size_t i = 0; i < sizeof subdirs / sizeof subdirs[0]; i++)
    if (!join(path, sizeof path, tmp, subdirs[i])) rmdir(path);
  rmdir(tmp);
  return 0;
}

int emit_embedded(const mbc_unit *u, const char *dir, int integrator, double step) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.pkg", dir);
  int st = write_package(u, dir, tmp, integrator, step);
  if (st) remove_partial(tmp, u->lowered->m.name);
  return st;
}
