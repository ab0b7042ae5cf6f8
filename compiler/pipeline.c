/* pipeline.c: the stages in order, each product built once into the unit. */
#include <stdio.h>
#include <string.h>

#include "diag.h"
#include "unit.h"

/* FNV-1a 64 step over n bytes */
static uint64_t fnv1a(uint64_t h, const unsigned char *b, size_t n) {
  for (size_t i = 0; i < n; i++) {
    h ^= b[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

/* the input hash (unit.h); 0 after reporting if the file cannot be read */
static int hash_input(mbc_unit *u) {
  FILE *f = fopen(u->path, "rb");
  if (!f) {
    diag_error(u->path, (ir_loc){0, 0}, "cannot read the model file again to hash it");
    return 2;
  }
  uint64_t h = 0xcbf29ce484222325ULL;
  unsigned char buf[8192];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = fnv1a(h, buf, n);
  int bad = ferror(f);
  fclose(f);
  if (bad) {
    diag_error(u->path, (ir_loc){0, 0}, "cannot read the model file again to hash it");
    return 2;
  }
  h = fnv1a(h, (const unsigned char *)"", 1);
  if (u->scene) h = fnv1a(h, (const unsigned char *)u->scene, strlen(u->scene));
  u->input_hash = h;
  return 0;
}

int mbc_unit_read(mbc_unit *u, const char *path, const char *scene) {
  memset(u, 0, sizeof *u);
  u->path = path;
  u->scene = scene;
  const char *slash = strrchr(path, '/');
  u->file_name = slash ? slash + 1 : path;
  u->ir = ir_read(path, scene);
  if (!u->ir) return 2;
  if (hash_input(u)) {
    mbc_unit_free(u);
    return 2;
  }
  return 0;
}

int mbc_unit_finish(mbc_unit *u, int verbose) {
  if (flex_reduce(u->ir, &u->flex)) return 2;
  u->lowered = lower_model(u->ir, &u->flex);
  if (!u->lowered) {
    if (!diag_errors()) diag_error(u->path, (ir_loc){0, 0}, "out of memory while lowering");
    return 2;
  }
  if (assemble_model(u->lowered, verbose)) return 2;
  /* the plan reads the assembled model: removed rows and the values at t = 0 */
  u->have_plan = !ldl_plan_build(u->lowered, &u->plan);
  return 0;
}

int mbc_unit_build(mbc_unit *u, const char *path, const char *scene, int verbose) {
  if (mbc_unit_read(u, path, scene)) return 2;
  return mbc_unit_finish(u, verbose);
}

void mbc_unit_free(mbc_unit *u) {
  if (u->have_plan) ldl_plan_free(&u->plan);
  if (u->lowered) lower_free(u->lowered);
  flex_product_free(&u->flex);
  if (u->ir) ir_free(u->ir);
  memset(u, 0, sizeof *u);
}
