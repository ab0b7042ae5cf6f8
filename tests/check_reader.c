/* check_reader.c: reads a model with ir_read and prints a one-line summary.
 * Usage: check_reader MODEL.yaml [SCENE]; exit 0 if read, 2 if not. */
#include <stdio.h>

#include "ir.h"

int main(int argc, char **argv) {
  if (argc < 2 || argc > 3) {
    fprintf(stderr, "usage: %s MODEL.yaml [SCENE]\n", argv[0]);
    return 1;
  }
  ir_model *m = ir_read(argv[1], argc == 3 ? argv[2] : NULL);
  if (m == NULL)
    return 2;
  printf("%s%s%s: %d bodies (incl. ground), %d joints, %d drivers, %d forces, %d outputs, "
         "end_time %g, output_step %g\n",
         m->name, m->scene ? " scene " : "", m->scene ? m->scene : "", m->nbodies, m->njoints,
         m->ndrivers, m->nforces, m->noutputs, m->sim.end_time, m->sim.output_step);
  ir_free(m);
  return 0;
}
