/* outfile.c: write to PATH.<pid>.part, rename when complete. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <string.h>
#include <unistd.h>

#include "diag.h"
#include "outfile.h"

int out_file_open(out_file *o, const char *path) {
  memset(o, 0, sizeof *o);
  int k = snprintf(o->path, sizeof o->path, "%s", path);
  if (k < 0 || (size_t)k >= sizeof o->path) {
    diag_error(NULL, (ir_loc){0, 0}, "output path too long: '%s'", path);
    return 2;
  }
  /* the process's own name: two mbcc writing one output at once never write
     into each other's file, and the last complete one wins */
  snprintf(o->part, sizeof o->part, "%s.%ld.part", path, (long)getpid());
  o->f = fopen(o->part, "w");
  if (!o->f) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s': %s", o->part, strerror(errno));
    return 2;
  }
  return 0;
}

int out_file_commit(out_file *o) {
  if (!o->f) return 2;
  int bad = ferror(o->f);
  bad |= fclose(o->f) != 0;
  o->f = NULL;
  if (bad) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot write '%s'", o->part);
    remove(o->part);
    return 2;
  }
  if (rename(o->part, o->path)) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot move '%s' to '%s': %s", o->part, o->path, strerror(errno));
    remove(o->part);
    return 2;
  }
  return 0;
}

void out_file_abort(out_file *o) {
  if (o->f) fclose(o->f);
  o->f = NULL;
  if (o->part[0]) remove(o->part);
}
