/* outfile.h: every file mbcc writes is written as PATH.<pid>.part (the
 * process's own: two mbcc at once never share it) and renamed to PATH only
 * when complete, so that an error never leaves a half-written file under the
 * final name. */
#ifndef MBCC_OUTFILE_H
#define MBCC_OUTFILE_H

#include <stdio.h>

typedef struct {
  FILE *f;
  char path[4096];
  char part[4200];
} out_file;

/* Open PATH.<pid>.part for writing.  0, or 2 after reporting. */
int out_file_open(out_file *o, const char *path);
/* Close it and, if every write succeeded, rename it to PATH.  0, or 2 after
 * reporting (the .part file is then removed). */
int out_file_commit(out_file *o);
/* Close and remove the .part file (another file of the same output failed) */
void out_file_abort(out_file *o);

#endif
