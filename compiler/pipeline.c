/* pipeline.c: the stages in order, each product built once into the unit. */
#include <string.h>

#include "diag.h"
#include "unit.h"

int mbc_unit_read(mbc_unit *u, const char *path, const char *scene) {
  memset(u, 0, sizeof *u);
  u->path = path;
  u->scene = scene;
  u->ir = ir_read(path, scene);
  return u->ir ? 0 : 2;
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
