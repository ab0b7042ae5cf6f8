/* emit.c: writes generated/<model>/: <model>.h, <model>.c (element tables,
 * the pattern of K, and the specialized straight-line evaluation that fills
 * only the varying entries of K each step) and main.c (the simulator).
 * Output is byte-reproducible: no timestamps, doubles printed with %.17g. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "paths.h"
#include "params.h"
#include "unit.h"
#include "diag.h"
#include "emit.h"
#include "emit_float.h"
#include "emit_ldl.h"
#include "emit_force.h"
#include "emit_rows.h"
#include "emit_split.h"
#include "emit_loops.h"
#include "emit_files.h"
#include "element.h"
#include "emit_util.h"
#include "sym.h"
#include "outfile.h"
#include "version.h"
#include "flex.h"
#include "lower.h"

/* Free text (a file path, a scene name) made safe inside a C comment: no
 * comment end or start, no line break or control character, no trigraph.
 * One of four rotating buffers. */
static const char *comment_text(const char *s) {
  static char buf[4][1024];
  static int next;
  char *out = buf[next++ & 3];
  size_t n = 0;
  for (const char *p = s; *p && n + 4 < sizeof buf[0]; p++) {
    unsigned char c = (unsigned char)*p;
    out[n++] = c < 0x20 || c == 0x7f ? '?' : (char)c;
    if ((c == '*' && p[1] == '/') || (c == '/' && p[1] == '*') || (c == '?' && p[1] == '?')) out[n++] = ' ';
  }
  out[n] = 0;
  return out;
}

/* file:line:col of a YAML element, the file named in its own directory (as
 * mbc_unit's file_name): the comment does not depend on how the path was typed */
static void loc_comment(FILE *f, const lmodel *L, ir_loc loc) {
  const char *file = diag_loc_file(loc, L->ir->path); /* an included file's element: that file */
  const char *slash = strrchr(file, '/');
  loc = diag_loc_in_file(loc);
  fprintf(f, "%s:%d:%d", comment_text(slash ? slash + 1 : file), loc.line, loc.col);
}

static void emit_flex_tables(emit_ctx *cx, int b);
static void emit_flex_contract(emit_ctx *cx, int b);

/* entry (i, l) of a flexible body's mass matrix from the moving blocks of
 * mb_flex_assemble (runtime/core/mb_flex.h): AS = A S~, AS1 = A S1, cs.J, cs.Gw */
static void flex_moving_entry(char *e, size_t size, int i, int l) {
  int bi = i < 3 ? 0 : i < 6 ? 1 : 2, bl = l < 3 ? 0 : l < 6 ? 1 : 2;
  if (bi > bl) { int t = i; i = l; l = t; t = bi; bi = bl; bl = t; } /* symmetric */
  if (bi == 0 && bl == 1) snprintf(e, size, "-AS[%d]", 3 * i + (l - 3));
  else if (bi == 0 && bl == 2) snprintf(e, size, "AS1[%d]", 3 * (l - 6) + i);
  else if (bi == 1 && bl == 1) snprintf(e, size, "cs.J[%d]", 3 * (i - 3) + (l - 3));
  else if (bi == 1 && bl == 2) snprintf(e, size, "cs.Gw[%d]", 3 * (l - 6) + (i - 3));
  else snprintf(e, size, "0 /* constant block */");
}

static int all_zero(const double *x, int n) {
  for (int i = 0; i < n; i++)
    if (x[i] != 0) return 0;
  return 1;
}

static const char *body_kind_name(mb_body_kind kind) {
  switch (kind) {
  case MB_BODY_RIGID: return "MB_BODY_RIGID";
  case MB_BODY_VIRTUAL: return "MB_BODY_VIRTUAL";
  case MB_BODY_FLEXIBLE: return "MB_BODY_FLEXIBLE";
  }
  return "0";
}

static const char *prim_kind_name(mb_prim_kind kind) {
  switch (kind) {
  case MB_PRIM_SPH: return "MB_PRIM_SPH";
  case MB_PRIM_DOT1: return "MB_PRIM_DOT1";
  case MB_PRIM_DOT2: return "MB_PRIM_DOT2";
  case MB_PRIM_DIST: return "MB_PRIM_DIST";
  case MB_PRIM_ROT: return "MB_PRIM_ROT";
  case MB_PRIM_TRANS: return "MB_PRIM_TRANS";
  }
  return "0";
}

static const char *profile_kind_name(mb_profile_kind kind) {
  switch (kind) {
  case MB_PROFILE_CONSTANT: return "MB_PROFILE_CONSTANT";
  case MB_PROFILE_CONSTANT_VELOCITY: return "MB_PROFILE_CONSTANT_VELOCITY";
  case MB_PROFILE_POLYNOMIAL: return "MB_PROFILE_POLYNOMIAL";
  case MB_PROFILE_RAMP: return "MB_PROFILE_RAMP";
  case MB_PROFILE_SINE: return "MB_PROFILE_SINE";
  case MB_PROFILE_TABLE: return "MB_PROFILE_TABLE";
  }
  return "0";
}

static const char *law_kind_name(mb_law_kind kind) {
  switch (kind) {
  case MB_LAW_NONE: return "MB_LAW_NONE";
  case MB_LAW_LINEAR: return "MB_LAW_LINEAR";
  case MB_LAW_POWER: return "MB_LAW_POWER";
  case MB_LAW_TABLE: return "MB_LAW_TABLE";
  }
  return "0";
}

/* the run-time parameters the code takes: none when they were not bound
 * (the IR changed after reading, mbcc trade: the code then folds them) */
static int runtime_count(const mbc_unit *u) {
  const ir_model *ir = u->ir;
  if (u->overridden) return 0;
  int n = 0;
  for (int k = 0; k < ir->nparams; k++) n += ir->params[k].runtime;
  return n;
}

static void limit_literal(FILE *f, double x) {
  if (isinf(x)) fputs(x < 0 ? "(mb_real)-HUGE_VAL" : "(mb_real)HUGE_VAL", f); /* explicit: no narrowing in C++ */
  else num(f, x);
}

/* a run-time coordinate: the C text of expression ir->uses[use] over p, or
 * the literal when use < 0 */
static void geometry_coordinate(FILE *f, const mbc_unit *u, int use, double literal) {
  if (use < 0) {
    num(f, literal);
    return;
  }
  fputc('(', f);
  expr_print_c(f, u->ir, u->ir->uses[use].expr, u->real_float ? "p" : "(double)p");
  fputc(')', f);
}

/* coordinate j of body b's lowered position: run-time or the literal r */
static void body_coordinate(FILE *f, const mbc_unit *u, int b, int j, double r) {
  const runtime_body *rb = mbc_runtime_body(u, b);
  geometry_coordinate(f, u, rb ? rb->use[j] : -1, r);
}

/* set_params's lines for run-time geometry (pipeline.c, bind_geometry): the
 * initial positions of bodies as given (q_given), and the offsets s = A^T (P - r) of the markers that follow them or
 * their run-time points; the simulator then re-assembles (mb_reassemble) */
static void emit_geometry_params(FILE *f, const mbc_unit *u) {
  const lmodel *L = u->lowered;
  for (int i = 0; i < u->nrbody; i++) {
    const runtime_body *rb = &u->rbody[i];
    for (int j = 0; j < 3; j++) {
      if (rb->use[j] < 0) continue;
      fprintf(f, "  q_given[%d] = (mb_real)", L->body[rb->body].qadr + j);
      geometry_coordinate(f, u, rb->use[j], 0);
      fprintf(f, "; /* body '%s', position %s */\n", L->body[rb->body].name, j == 0 ? "x" : j == 1 ? "y" : "z");
    }
  }
  for (int i = 0; i < u->nrmark; i++) {
    const runtime_marker *rm = &u->rmark[i];
    for (int r = 0; r < 3; r++) {
      if (rm->output >= 0) fprintf(f, "  outputs[%d].s[%d] = (mb_real)(", rm->output, r);
      else fprintf(f, "  markers[%d].s[%d] = (mb_real)(", rm->marker, r);
      if (rm->body < 0) {
        geometry_coordinate(f, u, rm->use[r], rm->P[r]);
      } else {
        int written = 0;
        for (int j = 0; j < 3; j++) {
          if (rm->frame_A[3 * j + r] == 0) continue; /* an exact zero: left out */
          if (written++) fputs(" + ", f);
          num(f, rm->frame_A[3 * j + r]);
          fputs(" * (", f);
          geometry_coordinate(f, u, rm->use[j], rm->P[j]);
          fputs(" - ", f);
          body_coordinate(f, u, rm->body, j, rm->frame_r[j]);
          fputc(')', f);
        }
        if (!written) fputc('0', f);
      }
      fprintf(f, "); /* %s, %s */\n", rm->what, r == 0 ? "x" : r == 1 ? "y" : "z");
    }
  }
}

/* set_params's lines for a force marker whose global point at t = 0 has
 * run-time coordinates (binding i, the marker's first): its offset in the
 * body's frame, s = A^T (P - r), the arithmetic of lower.c's add_marker with
 * P's run-time coordinates as expressions */
static void emit_marker_point(FILE *f, const mbc_unit *u, int i) {
  const ir_model *ir = u->ir;
  const runtime_binding *b = &u->bind[i];
  for (int e = 0; e < i; e++)
    if (u->bind[e].pool == BIND_MARKER_POINT && u->bind[e].index == b->index) return; /* written already */
  const ir_force *F = &ir->forces[u->lowered->force_ir[b->force]];
  const bool on_ground = u->lowered->marker[b->index].body < 0;
  const char *cast = u->real_float ? "p" : "(double)p";
  for (int r = 0; r < 3; r++) {
    fprintf(f, "  markers[%d].s[%d] = (mb_real)(", b->index, r);
    int written = 0;
    for (int j = 0; j < 3; j++) {
      int use = -1;
      for (int e = i; e < u->nbind; e++)
        if (u->bind[e].pool == BIND_MARKER_POINT && u->bind[e].index == b->index && u->bind[e].component == j)
          use = u->bind[e].use;
      /* a zero entry of A adds an exact zero: left out */
      if (on_ground ? j != r : b->frame_A[3 * j + r] == 0) continue;
      if (!on_ground) {
        if (written++) fputs(" + ", f);
        num(f, b->frame_A[3 * j + r]);
        fputs(" * (", f);
      }
      if (use >= 0) {
        fputc('(', f);
        expr_print_c(f, ir, ir->uses[use].expr, cast);
        fputc(')', f);
      } else {
        num(f, F->point[b->side][j]);
      }
      if (!on_ground) {
        fputs(" - ", f);
        body_coordinate(f, u, u->lowered->marker[b->index].body, j, b->frame_r[j]);
        fputc(')', f);
      }
    }
    fprintf(f, "); /* force '%s', point %d, %s */\n", F->name, b->side, r == 0 ? "x" : r == 1 ? "y" : "z");
  }
}

/* the run-time parameters: names, defaults, bounds, and set_params, which
 * writes the pool entries they set (pipeline.c, bind_runtime) */
static void emit_runtime_params(emit_ctx *cx) {
  const mbc_unit *u = cx->u;
  const ir_model *ir = u->ir;
  const lmodel *L = cx->L;
  FILE *f = cx->f;
  int n = runtime_count(u);
  if (!n) return;
  fputs("\n/* --- run-time parameters: the simulator's --set NAME=VALUE --- */\n", f);
  fprintf(f, "static const char *const param_names[%d] = {", n);
  for (int k = 0, j = 0; k < ir->nparams; k++)
    if (ir->params[k].runtime) fprintf(f, "%s\"%s\"", j++ ? ", " : "", ir->params[k].name);
  fputs("};\n", f);
  const char *what[3] = {"param_values", "param_min", "param_max"};
  for (int w = 0; w < 3; w++) {
    fprintf(f, "static const mb_real %s[%d] = {", what[w], n);
    for (int k = 0, j = 0; k < ir->nparams; k++) {
      const ir_param *P = &ir->params[k];
      if (!P->runtime) continue;
      if (j++) fputs(", ", f);
      limit_literal(f, w == 0 ? P->value : w == 1 ? P->min : P->max);
    }
    fputs("};\n", f);
  }
  fputs("static const char *set_params(const mb_model *m, const mb_real *p) {\n  (void)m;\n", f);
  /* first the values against their fields' rules: nothing is written when one breaks its rule */
  for (int i = 0; i < u->nbind; i++) {
    const runtime_binding *b = &u->bind[i];
    const ir_force *F = &ir->forces[L->force_ir[b->force]];
    const ir_expr_use *use = &ir->uses[b->use];
    if (use->rule == RULE_ANY) continue;
    fputs("  if (!(", f);
    expr_print_c(f, ir, use->expr, "(double)p");
    const char *file = diag_loc_file(use->loc, L->ir->path), *slash = strrchr(file, '/');
    ir_loc at = diag_loc_in_file(use->loc);
    char rule[1400];
    snprintf(rule, sizeof rule, "force '%s': %s at %s:%d:%d %s", F->name, use->field, slash ? slash + 1 : file,
             at.line, at.col, params_rule_text(use->rule));
    fprintf(f, " %s 0)) return \"", use->rule == RULE_POSITIVE ? ">" : ">=");
    for (const char *c = rule; *c; c++) /* a C string: quotes and backslashes escaped, no control characters */
      if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
      else fputc((unsigned char)*c < 0x20 ? '?' : *c, f);
    fputs("\";\n", f);
  }
  for (int i = 0; i < u->nbind; i++) {
    const runtime_binding *b = &u->bind[i];
    const ir_force *F = &ir->forces[L->force_ir[b->force]];
    const ir_expr_use *use = &ir->uses[b->use];
    if (b->pool == BIND_MARKER_POINT) {
      emit_marker_point(f, u, i);
      continue;
    }
    fprintf(f, "  /* force '%s', ", F->name); /* an included or subsystem file's line: that file's */
    loc_comment(f, L, use->loc);
    fputs(" */\n  ", f);
    if (b->pool == BIND_PRM) fprintf(f, "force_prm[%d] = (mb_real)", b->index);
    else fprintf(f, "force_laws[%d].%s = (mb_real)", b->index, b->pool == BIND_LAW_COEF ? "coef" : "exponent");
    /* in float the expression stays float: a (double) would compute it in
     * double (software double on a single-precision FPU) */
    expr_print_c(f, ir, use->expr, u->real_float ? "p" : "(double)p");
    fputs(";\n", f);
  }
  emit_geometry_params(f, u);
  fputs("  return NULL;\n}\n", f);
  if (!u->nrmark && !u->nrbody) return;
  /* which parameters move the assembly, and the rows that must stay redundant */
  fprintf(f, "static const unsigned char param_geometry[%d] = {", n);
  for (int k = 0, j = 0; k < ir->nparams; k++)
    if (ir->params[k].runtime) fprintf(f, "%s%d", j++ ? ", " : "", mbc_param_moves_assembly(u, k));
  fputs("};\n", f);
  if (!L->nremoved) return;
  fprintf(f, "static const mb_rowdef redundant_rows[%d] = {\n", L->nremoved);
  for (int r = 0; r < L->nremoved; r++) {
    const mb_rowdef *R = &L->removed_row[r];
    fprintf(f, "  {.kind = %s, .m0 = %d, .m1 = %d, .a = %d, .b = %d", prim_kind_name(R->kind), R->m0, R->m1, R->a, R->b);
    if (R->L != 0) { fputs(", .L = ", f); num(f, R->L); }
    fprintf(f, ", .profile = %d, .joint = %d, .driver = %d},\n", R->profile, R->joint, R->driver);
  }
  fputs("};\n", f);
  fprintf(f, "static const char *const redundant_names[%d] = {\n", L->nremoved);
  for (int r = 0; r < L->nremoved; r++) {
    fputs("  \"", f);
    for (const char *c = L->removed_desc[r]; *c; c++)
      if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
      else fputc((unsigned char)*c < 0x20 ? '?' : *c, f);
    fputs("\",\n", f);
  }
  fputs("};\n", f);
}

/* the force records (kind and addresses) and their pools: force_prm, force_laws */
static void emit_force_tables(emit_ctx *cx) {
  FILE *f = cx->f;
  const lmodel *L = cx->L;
  const mb_model *m = &L->m;
  /* run-time parameters write the pools (set_params): then not const */
  const char *pool_const = runtime_count(cx->u) ? "" : "const ";
  fprintf(f, "static const mb_forcedef forces[%d] = {\n", m->nforce);
  for (int k = 0; k < m->nforce; k++) {
    const mb_forcedef *d = &L->force[k];
    const ir_force *F = &L->ir->forces[L->force_ir[k]];
    fprintf(f, "  /* force '%s' (", F->name);
    loc_comment(f, L, F->loc);
    fprintf(f, ") */\n  {.kind = %s, .m0 = %d, .m1 = %d, .padr = %d, .pnum = %d",
            d->kind == MB_FORCE_SUPERELEMENT ? "MB_FORCE_SUPERELEMENT" : force_element(F->kind)->runtime_kind_name,
            d->m0, d->m1, d->padr, d->pnum);
    if (d->lnum) fprintf(f, ", .ladr = %d, .lnum = %d", d->ladr, d->lnum);
    if (d->snum) fprintf(f, ", .sadr = %d, .snum = %d", d->sadr, d->snum);
    fprintf(f, ", .profile = %d", d->profile);
    if (d->local) fputs(", .local = 1", f);
    fputs("},\n", f);
  }
  fputs("};\n", f);
  if (m->nforce_prm) {
    fprintf(f, "static %smb_real force_prm[%d] = {\n", pool_const, m->nforce_prm);
    for (int k = 0; k < m->nforce; k++) {
      const mb_forcedef *d = &L->force[k];
      if (!d->pnum) continue;
      const ir_force *F = &L->ir->forces[L->force_ir[k]];
      fprintf(f, "  /* %d: force '%s': %s */", d->padr, F->name, force_element(F->kind)->prm_layout);
      int group = d->kind == MB_FORCE_FIELD ? MB_FIELD_K : 0; /* d0 on a line of its own */
      for (int i = 0; i < d->pnum; i++) {
        fputs(i == 0 || (i >= group && (i - group) % 6 == 0) ? "\n  " : " ", f);
        num(f, L->force_prm[d->padr + i]);
        fputc(',', f);
      }
      fputc('\n', f);
    }
    fputs("};\n", f);
  }
  if (m->nforce_law) {
    fprintf(f, "static %smb_law force_laws[%d] = {\n", pool_const, m->nforce_law);
    for (int k = 0; k < m->nforce; k++) {
      const mb_forcedef *d = &L->force[k];
      for (int l = 0; l < d->lnum; l++) {
        const mb_law *law = &L->force_law[d->ladr + l];
        const ir_force *F = &L->ir->forces[L->force_ir[k]];
        fprintf(f, "  /* %d: force '%s', %s */\n  {.kind = %s", d->ladr + l, F->name,
                force_element(F->kind)->law_names[l], law_kind_name(law->kind));
        if (law->coef != 0) { fputs(", .coef = ", f); num(f, law->coef); }
        if (law->exponent != 0) { fputs(", .exponent = ", f); num(f, law->exponent); }
        if (law->kind == MB_LAW_TABLE)
          fprintf(f, ", .ntable = %d, .table = force%d_law%d_table", law->ntable, k, l);
        fputs("},\n", f);
      }
    }
    fputs("};\n", f);
  }
  if (!cx->u->nrmark && !cx->u->nrbody) emit_runtime_params(cx);
}

/* the tables: bodies, markers, rows, forces, profiles, outputs */
static void emit_tables(emit_ctx *cx) {
  FILE *f = cx->f;
  const lmodel *L = cx->L;
  const mb_model *m = &L->m;
  fprintf(f, "/* --- element tables (also used for outputs and energy) --- */\n");
  for (int b = 0; b < m->nbody; b++)
    if (L->body[b].kind == MB_BODY_FLEXIBLE) {
      emit_flex_tables(cx, b);
      emit_flex_contract(cx, b);
    }
  if (L->nmodal_slot) int_array(f, "modal_slot", L->modal_slot, L->nmodal_slot);
  if (L->force_tslot) { /* force tangents for the implicit method (mb_model_force_tangent) */
    int_array(f, "force_tslot", L->force_tslot, m->nforce);
    int_array(f, "tangent_slot", L->tangent_slot, L->ntangent_slot);
  }
  for (int k = 0; k < m->nprofile; k++) {
    const mb_profile *p = &L->profile[k];
    if (p->kind != MB_PROFILE_TABLE) continue;
    char nm[64];
    snprintf(nm, sizeof nm, "profile%d_table", k);
    real_array(f, nm, p->table, 2 * p->ntable);
    snprintf(nm, sizeof nm, "profile%d_spline", k);
    real_array(f, nm, p->spline, p->ntable);
  }
  for (int k = 0; k < m->nforce; k++) {
    const mb_forcedef *d = &L->force[k];
    for (int l = 0; l < d->lnum; l++) {
      const mb_law *law = &L->force_law[d->ladr + l];
      if (law->kind == MB_LAW_TABLE) {
        char nm[64];
        snprintf(nm, sizeof nm, "force%d_law%d_table", k, l);
        real_array(f, nm, law->table, 2 * law->ntable);
      }
    }
  }
  if (m->nbody) {
    fprintf(f, "static const mb_body bodies[%d] = {\n", m->nbody);
    for (int b = 0; b < m->nbody; b++) {
      const mb_body *B = &L->body[b];
      if (b + 1 < L->ir->nbodies) {
        fprintf(f, "  /* body '%s' (", B->name);
        loc_comment(f, L, L->ir->bodies[b + 1].loc);
        fputs(") */\n", f);
      } else {
        fprintf(f, "  /* body '%s': massless, inserted for a joint on a flexible node */\n", B->name);
      }
      fprintf(f, "  {.name = \"%s\", .kind = %s", B->name, body_kind_name(B->kind));
      if (B->mass != 0) { fputs(", .mass = ", f); num(f, B->mass); }
      if (!all_zero(B->J, 9)) { fputs(", .J = ", f); vec(f, B->J, 9); }
      fprintf(f, ", .qadr = %d, .vadr = %d, .mslot = ", B->qadr, B->vadr);
      ivec(f, B->mslot, 12);
      if (B->kind == MB_BODY_FLEXIBLE)
        fprintf(f, ", .nm = %d, .flex = &flex%d, .mslotf = flex%d_mslot", B->nm, b, b);
      if (B->kind == MB_BODY_FLEXIBLE && B->stiff) fprintf(f, ", .stiff = &flex%d_stiff", b);
      fputs("},\n", f);
    }
    fputs("};\n", f);
  }
  if (m->nmarker) {
    bool runtime_markers = false; /* set_params writes their offsets: then not const */
    for (int k = 0; L->marker_runtime && k < m->nmarker; k++) runtime_markers |= L->marker_runtime[k];
    fprintf(f, "static %smb_markerdef markers[%d] = {\n", runtime_markers ? "" : "const ", m->nmarker);
    for (int k = 0; k < m->nmarker; k++) {
      const mb_markerdef *d = &L->marker[k];
      fprintf(f, "  /* %d: %s */\n  {.body = %d, .node = %d", k, L->marker_desc[k], d->body, d->node);
      if (!all_zero(d->s, 3)) { fputs(", .s = ", f); vec(f, d->s, 3); }
      fputs(", .C = ", f);
      vec(f, d->C, 9);
      fputs("},\n", f);
    }
    fputs("};\n", f);
  }
  if (m->nrow) {
    fprintf(f, "static const mb_rowdef rows[%d] = {\n", m->nrow);
    for (int r = 0; r < m->nrow; r++) {
      const mb_rowdef *R = &L->row[r];
      fprintf(f, "  /* %d: %s */\n  {.kind = %s, .m0 = %d, .m1 = %d, .a = %d, .b = %d", r, L->row_desc[r],
              prim_kind_name(R->kind), R->m0, R->m1, R->a, R->b);
      if (R->L != 0) { fputs(", .L = ", f); num(f, R->L); }
      fprintf(f, ", .profile = %d,\n   .slot = {", R->profile);
      ivec(f, R->slot[0], 6); fputs(", ", f); ivec(f, R->slot[1], 6);
      fputs("}, .slotT = {", f);
      ivec(f, R->slotT[0], 6); fputs(", ", f); ivec(f, R->slotT[1], 6);
      fputs("}", f);
      int any_constant = 0;
      for (int s = 0; s < 2; s++)
        for (int j = 0; j < 6; j++) any_constant |= R->constant[s][j];
      if (any_constant) {
        fputs(",\n   .constant = {", f);
        for (int s = 0; s < 2; s++) {
          int c[6];
          for (int j = 0; j < 6; j++) c[j] = R->constant[s][j];
          if (s) fputs(", ", f);
          ivec(f, c, 6);
        }
        fputs("}", f);
      }
      fprintf(f, ", .mslot = {%d, %d}, .joint = %d, .driver = %d},\n", R->mslot[0], R->mslot[1], R->joint,
              R->driver);
    }
    fputs("};\n", f);
  }
  if (m->nforce) emit_force_tables(cx);
  if (m->nprofile) {
    fprintf(f, "static const mb_profile profiles[%d] = {\n", m->nprofile);
    for (int k = 0; k < m->nprofile; k++) {
      const mb_profile *p = &L->profile[k];
      fprintf(f, "  {.kind = %s", profile_kind_name(p->kind));
      if (!all_zero(p->c, 8)) { fputs(", .c = ", f); vec(f, p->c, 8); }
      if (p->nc) fprintf(f, ", .nc = %d", p->nc);
      if (p->kind == MB_PROFILE_TABLE)
        fprintf(f, ", .ntable = %d, .table = profile%d_table, .spline = profile%d_spline", p->ntable, k, k);
      fputs("},\n", f);
    }
    fputs("};\n", f);
  }
  if (m->noutput) {
    bool runtime_points = false; /* set_params writes points of outputs (run-time geometry): then not const */
    for (int i = 0; i < cx->u->nrmark && runtime_count(cx->u); i++) runtime_points |= cx->u->rmark[i].output >= 0;
    fprintf(f, "static %smb_outputdef outputs[%d] = {\n", runtime_points ? "" : "const ", m->noutput);
    for (int k = 0; k < m->noutput; k++) {
      const mb_outputdef *o = &L->output[k];
      fprintf(f, "  /* output '%s' (", L->ir->outputs[k].name);
      loc_comment(f, L, L->ir->outputs[k].loc);
      fprintf(f, ") */\n  {.kind = %s, .body = %d", output_element(L->ir->outputs[k].kind)->runtime_kind_name,
              o->body);
      const char *vnames[5] = {".s", ".axis", ".u", ".axis_g", ".u_g"};
      const double *vals[5] = {o->s, o->axis, o->u, o->axis_g, o->u_g};
      for (int v = 0; v < 5; v++)
        if (!all_zero(vals[v], 3)) {
          fprintf(f, ", %s = ", vnames[v]);
          vec(f, vals[v], 3);
        }
      fprintf(f, ", .component = %d, .joint = %d, .reaction_marker = %d,\n   .driver_row = %d, .driver_marker = %d",
              o->component, o->joint, o->reaction_marker, o->driver_row, o->driver_marker);
      if (o->driver_rotation) fputs(", .driver_rotation = 1", f);
      fprintf(f, ", .node = %d, .chord = {%d, %d}, .scale = ", o->node, o->chord[0], o->chord[1]);
      num(f, o->scale);
      if (o->kind >= MB_OUT_FORCE && o->kind != MB_OUT_TYRE) { /* the fields of the newer kinds (zero for the others) */
        fprintf(f, ",\n   .element = %d, .quantity = %d, .body2 = %d, .node2 = %d, .s2 = ", o->element,
                o->quantity, o->body2, o->node2);
        vec(f, o->s2, 3);
        fprintf(f, ", .frame = %d, .jmarker = {%d, %d}, .joint_dofs = %d", o->frame, o->jmarker[0],
                o->jmarker[1], o->joint_dofs);
      }
      fprintf(f, ", .ncols = %d, .col = %d},\n", o->ncols, o->col);
    }
    fputs("};\n", f);
  }
  if (L->noutput_coef) { /* section outputs: coefficients on the modal coordinates */
    fprintf(f, "static const mb_real output_coef[%d] = {", L->noutput_coef);
    for (int i = 0; i < L->noutput_coef; i++) {
      fputs(i ? (i % 4 ? ", " : ",\n  ") : "\n  ", f);
      num(f, L->output_coef[i]);
    }
    fputs("};\n", f);
  }
  if (m->njoint) {
    fprintf(f, "static const char *const joint_names[%d] = {", m->njoint);
    for (int j = 0; j < m->njoint; j++) fprintf(f, "%s\"%s\"", j ? ", " : "", L->joint_name[j]);
    fputs("};\n", f);
  }
  if (m->ncols) {
    fprintf(f, "static const char *const col_names[%d] = {", m->ncols);
    for (int j = 0; j < m->ncols; j++) fprintf(f, "%s\"%s\"", j ? ", " : "", L->col_name[j]);
    fputs("};\n", f);
  }
  /* run-time geometry: set_params writes markers and outputs too, so after them */
  if (cx->u->nrmark || cx->u->nrbody) emit_runtime_params(cx);
}


/* c = the body columns of (dV, dW) at marker k; returns how many (6 or 6 + nm) */
int emit_cols(FILE *f, const lmodel *L, int k, const char *P, const char *dV, const char *dW,
                     const char *indent) {
  const mb_markerdef *d = &L->marker[k];
  const mb_body *B = &L->body[d->body];
  if (d->node >= 0 && !emit_node_static(B, d->node)) {
    if (emit_node_cols(f, L, k, dV, dW, indent)) return -1;
    return 6 + B->nm;
  }
  fprintf(f, "%smb_rigid_cols(&f%d, %s, %s, %s, c);\n", indent, d->body, P, dV, dW);
  return 6;
}

/* rhs[va..va+n-1] += c */
static void add_cols(FILE *f, int vadr, int n) {
  for (int j = 0; j < n; j++) fprintf(f, "    rhs[%d] += c[%d];\n", vadr + j, j);
}

void emit_add_cols(FILE *f, int vadr, int n) { add_cols(f, vadr, n); }
void emit_num(FILE *f, double x) { num(f, x); }

/* a flexible body's constant data: invariants, node shapes, mass-block slots */
static void emit_flex_tables(emit_ctx *cx, int b) {
  FILE *f = cx->f;
  const lmodel *L = cx->L;
  const mb_body *B = &L->body[b];
  const mb_flex *x = B->flex;
  int nm = x->nm, nn = x->nnode;
  char nm_[64];
  fprintf(f, "/* flexible body '%s': %d modes, %d nodes; frequencies (Hz):", B->name, nm, nn);
  for (int j = 0; j < nm; j++) fprintf(f, " %.6g", L->modes[b].freq_hz[j]);
  fputs(" */\n", f);
#define ARR(field, n)                                   \
  snprintf(nm_, sizeof nm_, "flex%d_" #field, b);       \
  real_array(f, nm_, (n) > 0 ? x->field : zero1, (n) > 0 ? (n) : 1);
  static const double zero1[1] = {0};
  ARR(S1, 3 * nm)
  ARR(E, 9 * nm)
  ARR(F, 9 * nm * nm)
  ARR(G, 3 * nm * nm)
  ARR(C0, 3 * nm)
  ARR(CPsi, 3 * nm)
  ARR(Mff, nm * nm)
  ARR(stiffness, nm)
  ARR(damping, nm)
  ARR(node_x, 3 * nn)
  ARR(node_X, 3 * nm * nn)
  ARR(node_Psi, 3 * nm * nn)
#undef ARR
  int nbk = 6 + nm;
  snprintf(nm_, sizeof nm_, "flex%d_mslot", b);
  int_array(f, nm_, B->mslotf, nbk * nbk);
  fprintf(f, "static const mb_flex flex%d = {%d, %d, ", b, nm, x->coupling);
  num(f, x->mass);
  fputs(", ", f);
  vec(f, x->S0, 3);
  fprintf(f, ", flex%d_S1, ", b);
  vec(f, x->J0, 9);
  fprintf(f, ",\n  flex%d_E, flex%d_F, flex%d_G, flex%d_C0, flex%d_CPsi, flex%d_Mff, flex%d_stiffness,\n"
             "  flex%d_damping, %d, flex%d_node_x, flex%d_node_X, flex%d_node_Psi",
          b, b, b, b, b, b, b, b, nn, b, b, b);
  fputs("};\n", f);
  if (B->stiff) { /* geometric stiffening (compiler/flex/stiffening.c) */
    snprintf(nm_, sizeof nm_, "flex%d_stiff_P", b);
    real_array(f, nm_, B->stiff->P, 3 * nm * nm);
    snprintf(nm_, sizeof nm_, "flex%d_stiff_R", b);
    real_array(f, nm_, B->stiff->R, 9 * nm * nm);
    fprintf(f, "static const mb_flex_stiff flex%d_stiff = {flex%d_stiff_P, flex%d_stiff_R, mb_flex_body_stiff};\n",
            b, b, b);
  }
}

/* "c->name[k] = c0 + sum_t coef_t * v[idx_t];" with the nonzero terms only,
 * formed in sym (one graph a statement, so each term's constant comes before
 * its symbol and the sum prints in the order it adds): a term after the first
 * with a negative coefficient subtracts its magnitude, the same number.
 * Returns -1 out of memory (nothing written). */
static int emit_sum(FILE *f, const char *lhs, double c0, const double *coef, const int *idx, int nt,
                    const char *v, long *nterm) {
  sym_graph g;
  sym_init(&g);
  sym_id sum = c0 != 0 || nt == 0 ? sym_const(&g, c0) : -1;
  for (int t = 0; t < nt; t++) {
    char name[32];
    snprintf(name, sizeof name, "%s[%d]", v, idx[t]);
    /* the constant made first (arguments' order of evaluation is unspecified) */
    sym_id c = sym_const(&g, sum < 0 ? coef[t] : fabs(coef[t]));
    sym_id term = sym_mul(&g, c, sym_symbol(&g, name));
    if (sum < 0) { sum = term; continue; }
    sum = coef[t] < 0 ? sym_sub(&g, sum, term) : sym_add(&g, sum, term);
  }
  int st = g.failed ? -1 : sym_print_block(f, &g, &sum, &lhs, 1, "s", "  ");
  sym_free(&g);
  *nterm += nt;
  return st;
}

/* a flexible body's per-step contractions (mb_flex_contract in
 * runtime/core/mb_flex.h) straight-line: the invariants' nonzero entries as
 * literal constants, zeros skipped (the tables are cleaned of rounding
 * residue in compiler/flex/flex.c, so the generic path sums the same terms) */
static void emit_flex_contract(emit_ctx *cx, int b) {
  FILE *f = cx->f;
  const lmodel *L = cx->L;
  const mb_body *B = &L->body[b];
  const mb_flex *x = B->flex;
  int nm = x->nm;
  int lin = x->coupling != MB_COUPLING_CONSTANT, quad = x->coupling == MB_COUPLING_FULL;
  double *coef = malloc(sizeof(double) * (size_t)(nm + 1));
  int *idx = malloc(sizeof(int) * (size_t)(nm + 1));
  if (!coef || !idx) { free(coef); free(idx); cx->failed = 1; return; }
  long nterm = 0;
  char lhs[64];
  fprintf(f, "\n/* flexible body '%s': the per-step contractions of its inertia invariants with\n"
             " * w = q[%d..%d] and wd = v[%d..%d] (mb_flex_contract, runtime/core/mb_flex.h), nonzero terms only */\n",
          B->name, B->qadr + 7, B->qadr + 7 + nm - 1, B->vadr + 6, B->vadr + 6 + nm - 1);
  fprintf(f, "static void flex%d_contract(const mb_real *w, const mb_real *wd, mb_flex_step *c) {\n", b);
  fputs("  (void)w;\n  (void)wd;\n", f);
  for (int i = 0; i < 3; i++) { /* S = S0 + S1 w, S1wd = S1 wd, Cw = CPsi wd */
    int nt = 0;
    for (int j = 0; j < nm && lin; j++)
      if (x->S1[3 * j + i] != 0) { coef[nt] = x->S1[3 * j + i]; idx[nt++] = j; }
    snprintf(lhs, sizeof lhs, "c->S[%d]", i);
    if (emit_sum(f, lhs, x->S0[i], coef, idx, nt, "w", &nterm)) cx->failed = 1;
    nt = 0;
    for (int j = 0; j < nm; j++)
      if (x->S1[3 * j + i] != 0) { coef[nt] = x->S1[3 * j + i]; idx[nt++] = j; }
    snprintf(lhs, sizeof lhs, "c->S1wd[%d]", i);
    if (emit_sum(f, lhs, 0, coef, idx, nt, "wd", &nterm)) cx->failed = 1;
    nt = 0;
    for (int j = 0; j < nm; j++)
      if (x->CPsi[3 * j + i] != 0) { coef[nt] = x->CPsi[3 * j + i]; idx[nt++] = j; }
    snprintf(lhs, sizeof lhs, "c->Cw[%d]", i);
    if (emit_sum(f, lhs, 0, coef, idx, nt, "wd", &nterm)) cx->failed = 1;
  }
  for (int j = 0; j < nm; j++) {
    fprintf(f, "  /* mode %d: Fw = sum_a w_a F_%d,a; Gw = C0 + sum_a w_a G_a,%d; Gd = sum_a wd_a G_a,%d */\n",
            j + 1, j, j, j);
    for (int i = 0; i < 9; i++) {
      int nt = 0;
      for (int a = 0; a < nm && lin; a++) {
        double v = x->F[9 * ((size_t)j * nm + a) + i];
        if (v != 0) { coef[nt] = v; idx[nt++] = a; }
      }
      snprintf(lhs, sizeof lhs, "c->Fw[%d]", 9 * j + i);
      if (emit_sum(f, lhs, 0, coef, idx, nt, "w", &nterm)) cx->failed = 1;
    }
    for (int i = 0; i < 3; i++) {
      int nt = 0;
      for (int a = 0; a < nm && lin; a++) {
        double v = x->G[3 * ((size_t)a * nm + j) + i];
        if (v != 0) { coef[nt] = v; idx[nt++] = a; }
      }
      snprintf(lhs, sizeof lhs, "c->Gw[%d]", 3 * j + i);
      if (emit_sum(f, lhs, x->C0[3 * j + i], coef, idx, nt, "w", &nterm)) cx->failed = 1;
      nt = 0;
      for (int a = 0; a < nm; a++) {
        double v = x->G[3 * ((size_t)a * nm + j) + i];
        if (v != 0) { coef[nt] = v; idx[nt++] = a; }
      }
      snprintf(lhs, sizeof lhs, "c->Gd[%d]", 3 * j + i);
      if (emit_sum(f, lhs, 0, coef, idx, nt, "wd", &nterm)) cx->failed = 1;
    }
  }
  /* J = J0 + sum_j w_j (2 tr(E_j) I - E_j - E_j^T) [+ sum_j w_j (tr(Fw_j) I - (Fw_j + Fw_j^T) / 2)] */
  fputs("  /* J = J0 + sum_j w_j J1_j", f);
  if (quad) fputs(" + sum_j w_j (tr(Fw_j) I - (Fw_j + Fw_j^T) / 2)", f);
  fputs(" */\n", f);
  for (int i = 0; i < 3; i++)
    for (int l = 0; l < 3; l++) {
      if (l < i) { /* J is symmetric: its lower triangle is the upper one's */
        fprintf(f, "  c->J[%d] = c->J[%d];\n", 3 * i + l, 3 * l + i);
        continue;
      }
      int nt = 0;
      for (int j = 0; j < nm && lin; j++) {
        const double *E = x->E + 9 * j;
        double v = 2 * (E[0] + E[4] + E[8]) * (i == l) - E[3 * i + l] - E[3 * l + i];
        if (v != 0) { coef[nt] = v; idx[nt++] = j; }
      }
      snprintf(lhs, sizeof lhs, "c->J[%d]", 3 * i + l);
      if (emit_sum(f, lhs, x->J0[3 * i + l], coef, idx, nt, "w", &nterm)) cx->failed = 1;
    }
  if (quad && lin) {
    fputs("  mb_real d[3] = {0, 0, 0}, o[3] = {0, 0, 0};\n  for (int j = 0; j < ", f);
    fprintf(f, "%d; j++) {\n", nm);
    /* the sums of the diagonal (tr(Fw_j) - Fw_j,ii) and of the off-diagonal
       pairs (Fw_j,il + Fw_j,li) over the modes first, written out: the loop
       over i and l with its (i == l) cost six times the instructions */
    fputs("    const mb_real *Fw = c->Fw + 9 * j;\n"
          "    mb_real tf = Fw[0] + Fw[4] + Fw[8];\n"
          "    d[0] += w[j] * (tf - Fw[0]);\n"
          "    d[1] += w[j] * (tf - Fw[4]);\n"
          "    d[2] += w[j] * (tf - Fw[8]);\n"
          "    o[0] += w[j] * (Fw[1] + Fw[3]);\n"
          "    o[1] += w[j] * (Fw[2] + Fw[6]);\n"
          "    o[2] += w[j] * (Fw[5] + Fw[7]);\n"
          "  }\n"
          "  c->J[0] += d[0];\n"
          "  c->J[4] += d[1];\n"
          "  c->J[8] += d[2];\n"
          "  c->J[1] -= 0.5 * o[0];\n"
          "  c->J[2] -= 0.5 * o[1];\n"
          "  c->J[5] -= 0.5 * o[2];\n"
          "  c->J[3] = c->J[1];\n"
          "  c->J[6] = c->J[2];\n"
          "  c->J[7] = c->J[5];\n", f);
  }
  fprintf(f, "  /* %ld multiply-adds with constants (the tables hold %ld entries) */\n}\n", nterm,
          (long)(3 * nm + 3 * nm + 3 * nm + 9 * nm * nm + 6 * nm * nm + 9 * nm));
  free(coef);
  free(idx);
}

/* the evaluation's body is written to a memory stream with its elements
 * marked; emit_split.c writes it as one function or, when large, in parts
 * (into files of their own when EF says so: emit_files.c) */
/* marker k is read by reader (a force i, or row r as nforce + r) with use u;
   spring: the reader is a spring, which reads only the point and its velocity */
static void mark_reader(char *use, char *springs_only, int *first, int k, char u, int reader, int spring) {
  if (use[k] < u) use[k] = u;
  if (!spring) springs_only[k] = 0;
  if (first[k] > reader) first[k] = reader;
}

/* the markers whose first reader is `reader`, at the top level of the
   evaluation (later readers in other parts of the split find them there) */
static void emit_markers_of(emit_ctx *cx, FILE *f, const char *use, const char *springs_only, const int *first,
                            char *computed, int reader, const loop_choice *lc) {
  const lmodel *L = cx->L;
  for (int k = 0; k < L->m.nmarker; k++) {
    if (first[k] != reader) continue;
    const mb_markerdef *d = &L->marker[k];
    fprintf(f, "  /* %s */\n", L->marker_desc[k]);
    if (use[k] == 1 && d->body >= 0 && emit_marker_is_frame(L, k)) {
      fprintf(f, "  /* the frame of body '%s' itself: the rows read f%d */\n", L->body[d->body].name, d->body);
      continue;
    }
    if (lc && lc->marker[k]) { /* a mixed loop form's marker: the loops computed it */
      fprintf(f, "  const mb_marker k%d = mk[%d]; /* looped */\n", k, k);
      continue;
    }
    int twin = emit_marker_node_twin(L, k, computed);
    if (twin >= 0) {
      fprintf(f, "  mb_marker k%d = k%d; /* the same node and axes */\n", k, twin);
      computed[k] = 1;
      continue;
    }
    fprintf(f, "  mb_marker k%d;\n", k);
    if (d->body < 0) {
      fprintf(f, "  mb_marker_ground(markers[%d].s, markers[%d].C, &k%d);\n", k, k, k);
    } else if (d->node >= 0 && emit_node_static(&L->body[d->body], d->node)) {
      fprintf(f, "  /* node %d: its mode shapes vanish: a rigid marker (mb_marker_rigid) */\n", d->node);
      if (emit_marker_special(f, L, k) < 0) cx->failed = 1;
    } else if (d->node >= 0) {
      if (emit_marker_node(f, L, k)) cx->failed = 1;
      computed[k] = 1; /* whole: a later marker on the same node and axes copies it */
    } else if (springs_only[k]) {
      fputs("  /* mb_marker_rigid's point and velocity (all a spring reads), its zeros and ones folded */\n", f);
      if (emit_marker_point_velocity(f, L, k) < 0) cx->failed = 1;
    } else {
      fputs("  /* mb_marker_rigid, its zeros and ones folded */\n", f);
      if (emit_marker_special(f, L, k) < 0) cx->failed = 1;
    }
  }
}

/* the body of marker k, when looped, is read by the straight-line code */
static void frame_read_through(const lmodel *L, const loop_choice *lc, int k, char *read) {
  int b = L->marker[k].body;
  if (b >= 0 && lc->body[b]) read[b] = 1;
}

/* a mixed loop form: the looped frames the straight-line elements read (the
 * bodies of their markers) as const locals f<b> from fr[] */
static int emit_frame_bridges(FILE *f, const lmodel *L, const loop_choice *lc) {
  const mb_model *m = &L->m;
  char *read = calloc((size_t)m->nbody + 1, 1);
  if (!read) return -1;
  for (int i = 0; i < m->nforce; i++) {
    const mb_forcedef *d = &L->force[i];
    if (lc->force[i]) continue;
    frame_read_through(L, lc, d->m0, read);
    if (d->m1 >= 0) frame_read_through(L, lc, d->m1, read);
    if (d->kind == MB_FORCE_SUPERELEMENT) /* its nodes 2.. follow marker m1 */
      for (int j = 1; j < (int)L->force_prm[d->padr + MB_SUPER_N]; j++) frame_read_through(L, lc, d->m1 + j, read);
  }
  for (int r = 0; r < m->nrow; r++)
    if (!lc->row[r]) {
      frame_read_through(L, lc, L->row[r].m0, read);
      frame_read_through(L, lc, L->row[r].m1, read);
    }
  for (int b = 0; b < m->nbody; b++)
    if (read[b]) /* (void): a reader may need only the marker */
      fprintf(f, "  const mb_frame f%d = fr[%d]; (void)f%d; /* body '%s', looped */\n", b, b, b, L->body[b].name);
  free(read);
  return 0;
}

/* the straight-line evaluation of the elements into sp: all of them (lc
 * NULL) or, in a mixed loop form, those lc does not loop; 0, or -1 out of
 * memory */
static int emit_eval_straight(emit_ctx *cx, eval_split *sp, const loop_choice *lc) {
  FILE *f = sp->body;
  const lmodel *L = cx->L;
  const mb_model *m = &L->m;
  /* the elements written here (a section's heading only when it has some) */
  int nbody = 0, nforce = 0, nrow = 0;
  for (int b = 0; b < m->nbody; b++) nbody += !lc || !lc->body[b];
  for (int i = 0; i < m->nforce; i++) nforce += !lc || !lc->force[i];
  for (int r = 0; r < m->nrow; r++) nrow += !lc || !lc->row[r];
  eval_split_mark(sp, "the body frames");
  /* frames and markers are separate variables, not arrays: the C compiler
     then drops the fields no row reads and keeps the rest compact, where an
     array of markers had to live whole in the stack frame (about a kilobyte
     more of L1 per evaluation on the flexible slider-crank) */
  if (nbody) fprintf(f, "\n  /* body frames */\n");
  for (int b = 0; b < m->nbody; b++) {
    if (lc && lc->body[b]) continue;
    if (b) eval_split_mark(sp, "the frame of body '%s'", L->body[b].name);
    fprintf(f, "  mb_frame f%d;\n  mb_frame_rigid(q + %d, v + %d, &f%d); /* body '%s' */\n", b,
            L->body[b].qadr, L->body[b].vadr, b, L->body[b].name);
  }
  /* use[k]: 0 no row or force element reads marker k (a joint whose rows were
     all removed as redundant): not computed; 1 only the spherical and dot-1
     rows of emit_row_special read it (they read the frame when the marker is
     its body's frame: then it is not stored); 2 forces or other rows pass it
     to kernels by address.  first[k]: its first reader, force i as i, row r
     as nforce + r; the marker is computed just before it.  Computed up front,
     all markers went through the eval split's shared struct whole (36 reals
     each, every field stored and copied back into each reading part): on the
     rigid car that copying was about a third of the evaluation. */
  int nreader = m->nforce + m->nrow;
  char *use = calloc(m->nmarker ? (size_t)m->nmarker : 1, 1);
  char *computed = calloc(m->nmarker ? (size_t)m->nmarker : 1, 1); /* node markers formed whole so far */
  char *springs_only = malloc(m->nmarker ? (size_t)m->nmarker : 1);
  int *first = malloc(sizeof *first * (size_t)(m->nmarker ? m->nmarker : 1));
  if (!use || !computed || !springs_only || !first) {
    free(use), free(computed), free(springs_only), free(first);
    return -1;
  }
  for (int k = 0; k < m->nmarker; k++) first[k] = nreader, springs_only[k] = 1;
  for (int i = 0; i < m->nforce; i++) {
    if (lc && lc->force[i]) continue;
    int spring = L->force[i].kind == MB_FORCE_SPRING;
    mark_reader(use, springs_only, first, L->force[i].m0, 2, i, spring);
    if (L->force[i].m1 >= 0) mark_reader(use, springs_only, first, L->force[i].m1, 2, i, spring);
    if (L->force[i].kind == MB_FORCE_SUPERELEMENT) /* its nodes 2.. follow marker m1 */
      for (int j = 1; j < (int)L->force_prm[L->force[i].padr + MB_SUPER_N]; j++)
        mark_reader(use, springs_only, first, L->force[i].m1 + j, 2, i, 0);
  }
  for (int r = 0; r < m->nrow; r++) {
    if (lc && lc->row[r]) continue;
    char u = emit_row_is_special(&L->row[r]) ? 1 : 2;
    mark_reader(use, springs_only, first, L->row[r].m0, u, m->nforce + r, 0);
    mark_reader(use, springs_only, first, L->row[r].m1, u, m->nforce + r, 0);
  }
  eval_split_mark(sp, "the body forces");
  if (nbody) fprintf(f, "\n  /* body forces: gravity and the quadratic-velocity (gyroscopic) terms */\n");
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &L->body[b];
    if (lc && lc->body[b]) continue;
    if (b) eval_split_mark(sp, "the forces of body '%s'", B->name);
    fprintf(f, "  /* body '%s' */\n", B->name);
    if (B->kind == MB_BODY_FLEXIBLE) {
      int nbk = 6 + B->nm;
      fprintf(f, "  {\n    mb_real AS[9], AS1[%d];\n    mb_flex_step cs;\n    flex%d_contract(q + %d, v + %d, &cs);\n",
              B->nm ? 3 * B->nm : 1, b, B->qadr + 7, B->vadr + 6); /* ISO C: no zero-size array */
      if (B->stiff) /* geometric stiffening: its terms added to the contractions */
        fprintf(f, "    mb_flex_stiff_step ss;\n    mb_flex_stiffen(&flex%d_stiff, &flex%d, q + %d, v + %d, &cs, &ss);\n",
                b, b, B->qadr + 7, B->vadr + 6);
      fprintf(f, "    mb_flex_forces(&flex%d, &cs, &f%d, q + %d, v + %d, (const mb_real[3])",
              b, b, B->qadr + 7, B->vadr + 6);
      vec(f, m->gravity, 3);
      fprintf(f, ", rhs + %d);\n", B->vadr);
      if (B->stiff) {
        fprintf(f, "    mb_flex_stiff_forces(&flex%d, &ss, &f%d, (const mb_real[3])", b, b);
        vec(f, m->gravity, 3);
        fprintf(f, ", rhs + %d);\n", B->vadr);
      }
      fprintf(f, "    /* the mass blocks that move (mb_flex_assemble without m I and Mff, set by init) */\n"
                 "    mb_flex_mass_moving(&flex%d, &cs, &f%d, AS, AS1);\n", b, b);
      if (B->stiff) fprintf(f, "    mb_flex_stiff_mass(&flex%d, &ss, &f%d, AS1);\n", b, b);
      for (int i = 0; i < nbk * nbk; i++)
        if (B->mslotf[i] >= 0 && flex_mass_entry(B->flex, B->stiff, i / nbk, i % nbk) == 2) {
          char e[48];
          flex_moving_entry(e, sizeof e, i / nbk, i % nbk);
          fprintf(f, "    Kx[%d] = %s;\n", B->mslotf[i], e);
        }
      fputs("  }\n", f);
      continue;
    }
    for (int j = 0; j < 3; j++) {
      fprintf(f, "  rhs[%d] = ", B->vadr + j);
      num(f, B->mass * m->gravity[j]);
      fputs(";\n", f);
    }
    int zeroJ = 1;
    for (int j = 0; j < 9; j++) zeroJ &= B->J[j] == 0;
    if (zeroJ) {
      fprintf(f, "  rhs[%d] = rhs[%d] = rhs[%d] = 0;\n", B->vadr + 3, B->vadr + 4, B->vadr + 5);
    } else {
      fprintf(f, "  mb_rigid_gyro((const mb_real[9])");
      vec(f, B->J, 9);
      fprintf(f, ", f%d.wl, rhs + %d);\n", b, B->vadr + 3);
    }
  }
  if (nforce) eval_split_mark(sp, "the force elements");
  if (nforce) fprintf(f, "\n  /* force elements */\n");
  for (int k = 0; k < m->nforce; k++) {
    const ir_force *F = &L->ir->forces[L->force_ir[k]];
    if (lc && lc->force[k]) continue;
    if (k) eval_split_mark(sp, "force '%s'", F->name);
    emit_markers_of(cx, f, use, springs_only, first, computed, k, lc);
    fprintf(f, "  { /* force '%s' (", F->name);
    loc_comment(f, L, F->loc);
    fputs(") */\n", f);
    if (force_element(F->kind)->emit_eval(f, L, k)) cx->failed = 1;
    fputs("  }\n", f);
  }
  eval_split_mark(sp, "the constraint rows");
  if (nrow || !lc) fprintf(f, "\n  /* constraint rows: D in both triangles of K, gamma, phi, phid */\n");
  fflush(f);
  long shared_from = ftell(f);
  if (emit_rows_shared(f, L, lc ? lc->row : NULL)) cx->failed = 1;
  /* its blocks, one per pair of bodies, are independent (emit_rows.c) */
  eval_split_mark_lines(sp, shared_from, "  /* relative rotation", "the relative rotations of a pair of bodies");
  for (int r = 0; r < m->nrow; r++) {
    const mb_rowdef *R = &L->row[r];
    if (lc && lc->row[r]) continue;
    eval_split_mark(sp, "row %d (%s)", r, L->row_desc[r]);
    emit_markers_of(cx, f, use, springs_only, first, computed, m->nforce + r, lc);
    fprintf(f, "  /* row %d: %s (", r, L->row_desc[r]);
    loc_comment(f, L, L->row_loc[r]);
    fputs(") */\n", f);
    int special = emit_row_special(f, L, r);
    if (special < 0) cx->failed = 1;
    if (special) continue;
    switch (R->kind) {
    case MB_PRIM_SPH: fprintf(f, "  mb_prim_sph(&k%d, &k%d, %d, &r);\n", R->m0, R->m1, R->a); break;
    case MB_PRIM_DOT1: fprintf(f, "  mb_prim_dot1(&k%d, &k%d, %d, %d, &r);\n", R->m0, R->m1, R->a, R->b); break;
    case MB_PRIM_DOT2: fprintf(f, "  mb_prim_dot2(&k%d, &k%d, %d, zero3, &r);\n", R->m0, R->m1, R->a); break;
    case MB_PRIM_DIST:
      fprintf(f, "  mb_prim_dist(&k%d, &k%d, ", R->m0, R->m1);
      num(f, R->L);
      fputs(", &r);\n", f);
      break;
    case MB_PRIM_ROT:
      fprintf(f, "  mb_profile_eval(&profiles[%d], t, x);\n  mb_prim_rot(&k%d, &k%d, x, &r);\n", R->profile, R->m0, R->m1);
      break;
    case MB_PRIM_TRANS:
      fprintf(f, "  mb_profile_eval(&profiles[%d], t, x);\n  mb_prim_dot2(&k%d, &k%d, 2, x, &r);\n", R->profile, R->m0, R->m1);
      break;
    }
    fprintf(f, "  phi[%d] = r.phi;\n  phid[%d] = mb_row_phidot(&r, &k%d, &k%d);\n"
               "  rhs[%d] = mb_row_gamma(&r, &k%d, &k%d);\n", r, r, R->m0, R->m1,
            m->nv + r, R->m0, R->m1);
    for (int s = 0; s < 2; s++) {
      int mk = s ? R->m1 : R->m0;
      if (!emit_row_side_varies(L, r, s)) continue;
      static const char *const cs[6] = {"c[0]", "c[1]", "c[2]", "c[3]", "c[4]", "c[5]"};
      char P[32], dV[32], dW[32];
      snprintf(P, sizeof P, "k%d.P", mk);
      snprintf(dV, sizeof dV, "r.dV[%d]", s);
      snprintf(dW, sizeof dW, "r.dW[%d]", s);
      if (emit_cols(f, L, mk, P, dV, dW, "  ") < 0 || emit_row_stores(f, L, r, s, cs, "  ")) cx->failed = 1;
    }
  }
  free(use);
  free(computed);
  free(springs_only);
  free(first);
  return 0;
}

/* the evaluation <m>_eval; returns 1 when it is in the loop form (one
 * function), else 0 (straight-line, into EF's files when it is in parts) */
static int emit_eval(emit_ctx *cx, emit_files *EF) {
  FILE *out = cx->f;
  eval_split sp;
  if (eval_split_begin(&sp)) { cx->failed = 1; return 0; }
  FILE *f = sp.body;
  const lmodel *L = cx->L;
  const char *nm = cx->nm;
  char head[1024];
  snprintf(head, sizeof head,
          "\n/* Fill the varying entries of K, rhs = [f; gamma], phi and phid = D v - nu at (t, q, v). */\n"
          "void %s_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,\n"
          "    mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid, void *work) {\n"
          "  static const mb_real zero3[3] = {0, 0, 0};\n"
          "  mb_row r;\n  mb_real c[6 + MB_MAX_MODES], x[3];\n"
          "  (void)m; (void)work; (void)t; (void)x; (void)c; (void)r; (void)zero3;\n"
          "  (void)Kx; (void)phi; (void)phid;\n",
          nm);
  loop_choice lc;
  int looped = emit_loops_choose(L, &lc);
  if (looped < 0) cx->failed = 1;
  if (looped > 0) { /* identical elements as loops over tables: one function */
    if (emit_loops_eval(out, f, L, &lc)) cx->failed = 1;
    if (lc.mixed) { /* the elements without a loop form follow, straight-line */
      sp.one_function = 1;
      fputs("\n  /* the elements without a loop form, straight-line (emit.c); the looped frames and\n"
            "     markers they read, from fr[] and mk[] */\n", f);
      if (emit_frame_bridges(f, L, &lc) || emit_eval_straight(cx, &sp, &lc)) cx->failed = 1;
    }
    loop_choice_free(&lc);
    if (eval_split_finish(&sp, out, nm, head, NULL) < 0) cx->failed = 1;
    return 1;
  }
  if (emit_eval_straight(cx, &sp, NULL)) cx->failed = 1;
  if (eval_split_finish(&sp, out, nm, head, emit_files_eval_hooks(EF)) < 0) cx->failed = 1;
  return 0;
}

/* init's statements per function when a large model's init is split: gcc's
 * dead store elimination grows with the square of the stores of one function
 * (measured: docs/architecture.md, "What a part costs the C compiler") */
#define INIT_PART_LINES 500L

/* MBCC_INIT_PART_LINES overrides it, for measurement and tests (0: one function) */
static long init_part_lines(void) { return emit_size_setting("MBCC_INIT_PART_LINES", INIT_PART_LINES); }

/* one element's start in init's body (a body's or a row's statements): a
 * part of a split init may begin there */
typedef struct {
  long at, lines; /* offset in the text, lines before it */
} init_mark;

static long count_lines(const char *text, long a, long b) {
  long n = 0;
  for (long i = a; i < b; i++) n += text[i] == '\n';
  return n;
}

/* a mark where the text written to f (a memory stream over 'text') ends now */
static void add_init_mark(FILE *f, char *const *text, init_mark *mark, int *nmark) {
  fflush(f); /* the stream's text (*text, which fflush may move) is valid up to ftell */
  long at = ftell(f), from = *nmark ? mark[*nmark - 1].at : 0;
  mark[*nmark].at = at;
  mark[*nmark].lines = (*nmark ? mark[*nmark - 1].lines : 0) + count_lines(*text, from, at);
  (*nmark)++;
}

/* the body of init (its statements after the zeroing), marks at its elements */
static void emit_init_body(emit_ctx *cx, FILE *f, init_mark *mark, int *nmark, char **text) {
  const lmodel *L = cx->L;
  const mb_model *m = &L->m;
  loop_choice lc;
  int looped = emit_loops_choose(L, &lc);
  if (looped < 0) cx->failed = 1;
  if (looped > 0) { /* loops over the tables (no marks); a mixed form's flexible bodies below */
    int mixed = lc.mixed;
    loop_choice_free(&lc);
    emit_loops_init(f, L);
    if (!mixed) return;
  }
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &L->body[b];
    if (looped > 0 && B->kind != MB_BODY_FLEXIBLE) continue;
    add_init_mark(f, text, mark, nmark);
    if (B->kind == MB_BODY_FLEXIBLE) {
      /* the constant entries of the mass block: computed by the kernel at rest */
      int nbk = 6 + B->nm, any = 0;
      for (int i = 0; i < nbk * nbk; i++) any |= B->mslotf[i] >= 0 && flex_mass_entry(B->flex, B->stiff, i / nbk, i % nbk) == 1;
      if (!any) continue;
      fprintf(f, "  { /* body '%s': constant mass entries */\n    mb_real Mb[%d], fb[%d], w[%d] = {0};\n"
                 "    mb_frame f0 = {{0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};\n"
                 "    mb_flex_body(&flex%d, &f0, w, w, w, Mb, fb);\n",
              B->name, nbk * nbk, nbk, nbk, b);
      for (int i = 0; i < nbk * nbk; i++)
        if (B->mslotf[i] >= 0 && flex_mass_entry(B->flex, B->stiff, i / nbk, i % nbk) == 1)
          fprintf(f, "    Kx[%d] = Mb[%d];\n", B->mslotf[i], i);
      fputs("  }\n", f);
      continue;
    }
    if (B->kind != MB_BODY_RIGID) continue;
    fprintf(f, "  /* body '%s': mass and inertia */\n", B->name);
    for (int j = 0; j < 12; j++)
      if (B->mslot[j] >= 0) {
        fprintf(f, "  Kx[%d] = ", B->mslot[j]);
        num(f, j < 3 ? B->mass : B->J[j - 3]);
        fputs(";\n", f);
      }
  }
  if (looped > 0) { fflush(f); return; } /* the rows' constant entries: in emit_loops_init's loop */
  for (int r = 0; r < m->nrow; r++) {
    const mb_rowdef *R = &L->row[r];
    add_init_mark(f, text, mark, nmark);
    for (int s = 0; s < 2; s++)
      for (int j = 0; j < 6; j++)
        if (R->constant[s][j] && R->slot[s][j] >= 0)
          fprintf(f, "  Kx[%d] = Kx[%d] = %d; /* row %d: %s */\n", R->slot[s][j], R->slotT[s][j],
                  s ? 1 : -1, r, L->row_desc[r]);
  }
  fflush(f);
}

static void emit_init(emit_ctx *cx) {
  FILE *out = cx->f;
  const char *nm = cx->nm;
  const mb_model *m = &cx->L->m;
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  init_mark *mark = malloc(sizeof *mark * (size_t)(m->nbody + m->nrow + 1));
  if (!f || !mark) {
    if (f) fclose(f);
    free(text);
    free(mark);
    cx->failed = 1;
    return;
  }
  int nmark = 0;
  emit_init_body(cx, f, mark, &nmark, &text);
  if (ferror(f)) cx->failed = 1;
  fclose(f);
  long total = count_lines(text, 0, (long)len);
  /* the parts: elements grouped greedily up to part_lines; a small
     init stays one function, as before */
  int nparts = 0;
  long part_lines = init_part_lines();
  if (part_lines > 0 && total > 2 * part_lines) {
    long from = 0, from_lines = 0;
    for (int i = 0; i <= nmark; i++) {
      long at = i < nmark ? mark[i].at : (long)len, lines = i < nmark ? mark[i].lines : total;
      if (lines - from_lines < part_lines && i < nmark) continue;
      if (at == from) continue;
      if (!nparts)
        fputs("\n#if defined(__GNUC__)\n#define INIT_NOINLINE __attribute__((noinline))\n#else\n"
              "#define INIT_NOINLINE\n#endif\n", out);
      fprintf(out, "\n/* part %d of init: %ld statement lines (init in parts of bounded size, so that the\n"
                   " * C compiler's cost per function stays bounded) */\n"
                   "static INIT_NOINLINE void %s_init_part%d(mb_real *Kx) {\n",
              nparts + 1, lines - from_lines, nm, nparts);
      fwrite(text + from, 1, (size_t)(at - from), out);
      fputs("}\n", out);
      nparts++;
      from = at;
      from_lines = lines;
    }
  }
  fprintf(out, "\n/* The constant entries of K (mass matrix, constant Jacobian entries); all else 0. */\n"
               "void %s_init(const mb_model *m, mb_real *Kx) {\n  (void)m;\n"
               "  for (int i = 0; i < %d; i++) Kx[i] = 0;\n", nm, m->nnz);
  if (nparts)
    for (int p = 0; p < nparts; p++) fprintf(out, "  %s_init_part%d(Kx);\n", nm, p);
  else
    fwrite(text, 1, len, out);
  fputs("}\n", out);
  free(text);
  free(mark);
}

/* the first comment lines of a generated file: its name, mbcc's version, the
 * model file (named in its own directory) and scene, the input hash (unit.h) */
static void emit_origin_of(emit_ctx *cx, const char *file) {
  const mbc_unit *u = cx->u;
  fprintf(cx->f, "/* %s: generated by mbcc " MBCC_VERSION " from %s%s%s. Do not edit.\n"
                 " * input hash (FNV-1a 64 of the model file and scene name): %016llx",
          file, comment_text(u->file_name), u->ir->scene ? ", scene " : "",
          u->ir->scene ? comment_text(u->ir->scene) : "",
          (unsigned long long)u->input_hash);
}

static void emit_origin(emit_ctx *cx, const char *ext) {
  char file[300];
  snprintf(file, sizeof file, "%s.%s", cx->nm, ext);
  emit_origin_of(cx, file);
}

static void emit_header(emit_ctx *cx) {
  FILE *f = cx->f;
  const mbc_unit *u = cx->u;
  const lmodel *L = cx->L;
  const char *nm = cx->nm, *U = cx->NM;
  const mb_model *m = &L->m;
  emit_origin(cx, "h");
  fputs(" */\n", f);
  fprintf(f, "#ifndef %s_H\n#define %s_H\n\n", U, U);
  if (u->real_float)
    fputs("/* generated for single precision: mb_real is float (link the float runtime) */\n"
          "#ifndef MB_REAL_FLOAT\n#define MB_REAL_FLOAT\n#endif\n", f);
  fputs("#include \"mb_model.h\"\n\n", f);
  fprintf(f, "#define %s_NQ %d   /* position coordinates */\n", U, m->nq);
  fprintf(f, "#define %s_NV %d   /* velocity coordinates */\n", U, m->nv);
  fprintf(f, "#define %s_NC %d   /* constraint rows */\n", U, m->nc);
  fprintf(f, "#define %s_N %d    /* dimension of K */\n", U, m->n);
  fprintf(f, "#define %s_NNZ %d  /* nonzeros of K */\n", U, m->nnz);
  fprintf(f, "#define %s_NCOLS %d /* output columns */\n\n", U, m->ncols);
  fputs("#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n", f);
  fprintf(f, "extern const mb_model %s_model;\n", nm);
  fprintf(f, "void %s_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,\n"
             "    mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid, void *work);\n", nm);
  emit_ldl_header(cx);
  fprintf(f, "void %s_init(const mb_model *m, mb_real *Kx);\n\n", nm);
  fputs("#ifdef __cplusplus\n}\n#endif\n\n#endif\n", f);
}

/* <m>.c into cx->f, a memory stream whose text is *text (*len bytes) after a
 * flush; with EF->file_bytes > 0 a large model's evaluation parts and LDL^T
 * go to EF's files instead, and so does a loop-form model's straight-line
 * LDL^T.  1: the caller writes the model again as one file (the parts read a
 * table emit_files cannot point at; a loop-form model's LDL^T is small),
 * else 0. */
static int emit_source(emit_ctx *cx, emit_files *EF, char **text, size_t *len) {
  FILE *f = cx->f;
  const lmodel *L = cx->L;
  const char *nm = cx->nm, *U = cx->NM;
  const mb_model *m = &L->m;
  emit_origin(cx, "c");
  fputs("\n", f);
  fprintf(f, " * %d bodies, %d constraint rows (%d redundant removed), %d degrees of freedom;\n"
             " * K = [M D^T; D 0] is %d x %d with %d nonzeros. */\n",
          m->nbody, m->nc, L->nredundant, L->dof, m->n, m->n, m->nnz);
  fprintf(f, "#include \"%s.h\"\n\n", nm);
  fprintf(f, "/* --- CSC pattern of K (both triangles) --- */\n");
  int_array(f, "Kp", L->Kp, m->n + 1);
  if (m->nnz) int_array(f, "Ki", L->Ki, m->nnz);
  fprintf(f, "\n/* --- assembled, consistent initial state --- */\n");
  if (m->nq) real_array(f, "q0", L->q0, m->nq);
  if (m->nv) real_array(f, "v0", L->v0, m->nv);
  if (runtime_count(cx->u) && (cx->u->nrmark || cx->u->nrbody)) {
    /* run-time geometry: the state as the file gives it, where the start-up
       re-assembly starts (as the compiler's did); set_params writes the
       run-time bodies' positions */
    fputs("/* as given, before assembly (the start of the re-assembly after --set) */\n", f);
    fprintf(f, "static mb_real q_given[%d] = {", m->nq + 1);
    for (int i = 0; i < m->nq; i++) {
      fputs(i % 4 ? ", " : (i ? ",\n  " : "\n  "), f);
      num(f, L->q_given[i]);
    }
    fputs(m->nq ? "\n};\n" : "0};\n", f);
    real_array(f, "v_given", L->v_given, m->nv);
  }
  fputc('\n', f);
  emit_tables(cx);
  emit_init(cx);
  int loop_form = emit_eval(cx, EF);
  /* A loop-form evaluation is one function of <m>.c, but its straight-line
     LDL^T's parts compile in parallel as a model in parts' do: in files of
     their own when they are larger than an evaluation that is split
     (two parts' text; emit_split.h) */
  const ldl_plan *plan = &cx->u->plan;
  long budget = eval_part_bytes();
  int ldl_alone = loop_form && EF->file_bytes > 0 && budget > 0 && cx->u->have_plan && plan->straight;
  int ldl;
  if (EF->active && (fflush(f) || emit_files_tables(EF, f, *text, *len))) return 1;
  if (EF->active || ldl_alone) {
    /* the LDL^T in files of its own; its wrappers for the model record stay */
    ldl_out out;
    FILE *lf = emit_files_ldl(EF, f, &out);
    if (!lf) { cx->failed = 1; return 0; }
    cx->f = lf;
    ldl = emit_ldl(cx, &out);
    cx->f = f;
    long bytes = emit_files_ldl_bytes(EF);
    if (bytes < 0) { cx->failed = 1; return 0; }
    if (ldl_alone && bytes <= 2 * budget) return 1;
  } else
    ldl = emit_ldl(cx, NULL);
  fprintf(f, "\nconst mb_model %s_model = {\n", nm);
  fprintf(f, "  .name = \"%s\",\n  .nbody = %d, .nmarker = %d, .nrow = %d, .nforce = %d,\n"
             "  .nprofile = %d, .noutput = %d, .njoint = %d,\n"
             "  .nq = %s_NQ, .nv = %s_NV, .nc = %s_NC, .n = %s_N, .nnz = %s_NNZ,\n",
          nm, m->nbody, m->nmarker, m->nrow, m->nforce, m->nprofile, m->noutput, m->njoint, U, U,
          U, U, U);
  /* every field in the order of mb_model's, as C++ wants designated initializers */
  fprintf(f, "  .body = %s, .marker = %s, .row = %s, .force = %s,\n",
          m->nbody ? "bodies" : "0", m->nmarker ? "markers" : "0", m->nrow ? "rows" : "0",
          m->nforce ? "forces" : "0");
  if (m->nforce_prm || m->nforce_law)
    fprintf(f, "  .force_prm = %s, .force_law = %s, .nforce_prm = %d, .nforce_law = %d,\n",
            m->nforce_prm ? "force_prm" : "0", m->nforce_law ? "force_laws" : "0", m->nforce_prm,
            m->nforce_law);
  fprintf(f, "  .profile = %s, .output = %s, ", m->nprofile ? "profiles" : "0", m->noutput ? "outputs" : "0");
  if (L->noutput_coef) fputs(".output_coef = output_coef, ", f);
  fprintf(f, ".joint_name = %s,\n", m->njoint ? "joint_names" : "0");
  fputs("  .gravity = ", f);
  vec(f, m->gravity, 3);
  fprintf(f, ",\n  .Kp = Kp, .Ki = %s, .modal_slot = %s, .q0 = %s, .v0 = %s,\n", m->nnz ? "Ki" : "0",
          L->nmodal_slot ? "modal_slot" : "0", m->nq ? "q0" : "0", m->nv ? "v0" : "0");
  fprintf(f, "  .ncols = %s_NCOLS, .col_name = %s,\n  .eval = %s_eval, .init = %s_init,\n", U,
          m->ncols ? "col_names" : "0", nm, nm);
  emit_ldl_fields(cx, ldl);
  if (runtime_count(cx->u)) {
    int n = runtime_count(cx->u);
    fprintf(f, "  .nparam = %d, .param_name = param_names, .param_value = param_values,\n"
               "  .param_min = param_min, .param_max = param_max, .set_params = set_params,\n", n);
  }
  if (L->force_tslot)
    fputs("  .force_tslot = force_tslot, .tangent_slot = tangent_slot,\n", f);
  if (runtime_count(cx->u) && (cx->u->nrmark || cx->u->nrbody))
    fprintf(f, "  .param_geometry = param_geometry, .q_given = q_given, .v_given = v_given,\n"
               "  .nredundant = %d, .redundant_row = %s, .redundant_name = %s,\n",
            L->nremoved, L->nremoved ? "redundant_rows" : "0", L->nremoved ? "redundant_names" : "0");
  fputs("};\n", f);
  if (EF->active && (fflush(f) || emit_files_keep(EF, f, *text, *len))) return 1;
  return 0;
}

/* the model's simulation settings as C statements on an mb_settings 's' */
static void settings_block(FILE *f, const ir_sim *s) {
  static const char *const integrators[] = {"MB_RK4", "MB_DOPRI5", "MB_GENALPHA", "MB_AUTO"};
  _Static_assert(sizeof integrators / sizeof *integrators == INTEGRATOR_AUTO + 1,
                 "one runtime integrator name per ir_integrator");
  fprintf(f, "  s.integrator = %s;\n", integrators[s->integrator]);
  const char *names[] = {"end_time", "output_step", "step", "rtol", "atol", "min_step", "max_step",
                         "alpha", "beta", "rho_inf"};
  const double vals[] = {s->end_time, s->output_step, s->step, s->rtol, s->atol, s->min_step,
                         s->max_step, s->baumgarte_alpha, s->baumgarte_beta, s->rho_inf};
  for (int i = 0; i < 10; i++) {
    fprintf(f, "  s.%s = ", names[i]);
    num(f, vals[i]);
    fputs(";\n", f);
  }
  fprintf(f, "  s.stabilization = %s;",
          s->stabilization == STAB_PROJECTION ? "MB_STAB_PROJECTION"
          : s->stabilization == STAB_BAUMGARTE ? "MB_STAB_BAUMGARTE" : "MB_STAB_NONE");
  if (s->equilibrium) fputs("\n  s.equilibrium = 1;", f); /* only when asked: other mains unchanged */
}

const char *emit_root_dir(void) {
  const char *r = getenv("MBCC_ROOT");
#ifdef MBCC_ROOT
  return r && *r ? r : MBCC_ROOT;
#else
  return r && *r ? r : ".";
#endif
}

/* templates/<name> with @MODEL@, @SETTINGS@ and @SOLVER@ filled in, written
 * to f; 0, or 2 after reporting */
static int fill_template(FILE *f, const mbc_unit *u, const char *name) {
  const lmodel *L = u->lowered;
  char path[4200];
  snprintf(path, sizeof path, "%s/%s", mbcc_templates_dir(), name);
  FILE *in = fopen(path, "r");
  if (!in) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot read the template '%s' (set MBCC_ROOT?)", path);
    return 2;
  }
  char line[1024];
  while (fgets(line, sizeof line, in)) {
    if (!strcmp(line, "@SETTINGS@\n")) {
      settings_block(f, &L->ir->sim);
      fputc('\n', f);
      continue;
    }
    for (char *p = line; *p;) {
      if (!strncmp(p, "@MODEL@", 7)) { fputs(L->m.name, f); p += 7; }
      else if (!strncmp(p, "@SOLVER@", 8)) {
        /* single precision has only the emitted LDL^T (KLU, LAPACK are double) */
        fputs(u->real_float || L->ir->sim.solver == SOLVER_LDL ? "ldl" : L->ir->sim.solver == SOLVER_DENSE ? "dense" : "klu", f);
        p += 8;
      } else fputc(*p++, f);
    }
  }
  fclose(in);
  return 0;
}

int emit_template(const mbc_unit *u, const char *name, const char *out) {
  out_file o;
  if (out_file_open(&o, out)) return 2;
  if (fill_template(o.f, u, name)) {
    out_file_abort(&o);
    return 2;
  }
  return out_file_commit(&o);
}

/* the files of the generated directory and what writes each (after them,
 * a large model's other files: emit_files.h) */
enum { OUT_HEADER, OUT_SOURCE, OUT_MAIN, NOUT };

/* <m>.c's text and, for a large model, its other files; 0, or -1 out of memory */
static int source_text(const mbc_unit *u, emit_files *EF, char **text, size_t *len) {
  for (int attempt = 0; attempt < 2; attempt++) {
    emit_files_init(EF, u->lowered->m.name);
    if (attempt) EF->file_bytes = 0; /* the parts read a table emit_files cannot point at */
    *text = NULL;
    *len = 0;
    FILE *f = open_memstream(text, len);
    if (!f) return -1;
    emit_ctx cx;
    emit_ctx_init(&cx, f, u);
    int again = emit_source(&cx, EF, text, len);
    int bad = fclose(f) != 0 || cx.failed || EF->failed;
    if (!bad && !again) return 0;
    free(*text);
    *text = NULL;
    emit_files_free(EF);
    if (bad) return -1;
  }
  return -1;
}

/* after a successful emission: the files of an earlier split emission that
 * this one did not write (only names of the split's own pattern), and the
 * private header when the evaluation is no longer in files */
static void remove_stale(const char *dir, const char *nm, char **old, const char *const *now, int nnow) {
  char path[4400], header[400];
  snprintf(header, sizeof header, "%s_parts.h", nm);
  int has_header = 0;
  for (int k = 0; k < nnow; k++) has_header |= !strcmp(now[k], header);
  for (int i = 0; old && old[i]; i++) {
    int keep = 0;
    for (int k = 0; k < nnow; k++) keep |= !strcmp(old[i], now[k]);
    size_t n = strlen(nm);
    int ours = !strncmp(old[i], nm, n) && (!strncmp(old[i] + n, "_eval", 5) || !strncmp(old[i] + n, "_ldl", 4));
    if (!keep && ours) {
      snprintf(path, sizeof path, "%s/%s", dir, old[i]);
      remove(path);
    }
  }
  if (old && !nnow) { /* one file now: the list goes */
    snprintf(path, sizeof path, "%s/%s.sources", dir, nm);
    remove(path);
  }
  if (old && !has_header) {
    snprintf(path, sizeof path, "%s/%s", dir, header);
    remove(path);
  }
}

int emit_model(const mbc_unit *u, const char *dir) {
  const char *nm = u->lowered->m.name;
  if (mkdir(dir, 0777) && errno != EEXIST) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot create directory '%s': %s", dir, strerror(errno));
    return 2;
  }
  emit_files EF;
  char *src = NULL;
  size_t srclen = 0;
  if (source_text(u, &EF, &src, &srclen)) {
    diag_error(NULL, (ir_loc){0, 0}, "out of memory while writing '%s/%s.c'", dir, nm);
    return 2;
  }
  int nextra = emit_files_count(&EF), nout = NOUT + nextra;
  /* every file is written as .part; renamed only when all of them are complete */
  out_file *out = calloc((size_t)nout, sizeof *out);
  const char **names = calloc((size_t)nextra + 1, sizeof *names);
  char **old = emit_files_read_list(dir, nm); /* of an earlier emission */
  int st = out && names ? 0 : 2;
  if (st) diag_error(NULL, (ir_loc){0, 0}, "out of memory while writing '%s'", dir);
  for (int i = 0; i < nout && !st; i++) {
    char path[4096];
    char *text = NULL;
    size_t len = 0;
    int k;
    if (i >= NOUT) {
      text = emit_files_text(&EF, i - NOUT, &names[i - NOUT], &len);
      k = text ? snprintf(path, sizeof path, "%s/%s", dir, names[i - NOUT]) : 0;
    } else
      k = snprintf(path, sizeof path, i == OUT_MAIN ? "%s/main.c" : i == OUT_HEADER ? "%s/%s.h" : "%s/%s.c", dir, nm);
    if (i >= NOUT && !text) {
      diag_error(NULL, (ir_loc){0, 0}, "out of memory while writing '%s'", dir);
      st = 2;
      break;
    }
    if (k < 0 || (size_t)k >= sizeof path) {
      diag_error(NULL, (ir_loc){0, 0}, "output directory name too long: '%s'", dir);
      free(text);
      st = 2;
      break;
    }
    if (out_file_open(&out[i], path)) { free(text); st = 2; break; }
    emit_ctx cx;
    emit_ctx_init(&cx, out[i].f, u);
    if (i == OUT_HEADER) emit_header(&cx);
    else if (i == OUT_SOURCE) fwrite(src, 1, srclen, out[i].f);
    else if (i == OUT_MAIN) st = fill_template(out[i].f, u, "main.c.in");
    else {
      if (!strstr(names[i - NOUT], ".sources")) { /* C: the origin comment first */
        emit_origin_of(&cx, names[i - NOUT]);
        fputs(" */\n", out[i].f);
      }
      fwrite(text, 1, len, out[i].f);
    }
    free(text);
    if (cx.failed) {
      diag_error(NULL, (ir_loc){0, 0}, "out of memory while writing '%s'", path);
      st = 2;
    }
  }
  /* single precision: float literals and float math in the model's .h and
     .c files (not in the hosted main.c), rewritten in the .part files */
  for (int i = 0; !st && u->real_float && i < nout; i++) {
    if (i == OUT_MAIN || (i >= NOUT && strstr(names[i - NOUT], ".sources"))) continue;
    if (fflush(out[i].f) || ferror(out[i].f) || emit_float_dialect(out[i].part)) {
      diag_error(NULL, (ir_loc){0, 0}, "cannot rewrite '%s' for single precision", out[i].part);
      st = 2;
    }
  }
  for (int i = 0; out && i < nout; i++) {
    if (!out[i].f) continue;
    if (st) out_file_abort(&out[i]);
    else st = out_file_commit(&out[i]);
  }
  if (!st) remove_stale(dir, nm, old, names, nextra);
  emit_files_list_free(old);
  free(names);
  free(out);
  free(src);
  emit_files_free(&EF);
  return st;
}
