/* paths.h: where mbcc finds its templates, the runtime headers and the
 * runtime library: an installed mbcc (PREFIX/bin/mbcc) or a build tree
 * (ROOT/B/mbcc) finds them relative to its own executable; see paths.c. */
#ifndef MBCC_PATHS_H
#define MBCC_PATHS_H

const char *mbcc_templates_dir(void);  /* holds main.c.in */
const char *mbcc_include_dir(int k);   /* k = 0, 1: -I directories ("" when unused) */
const char *mbcc_runtime_lib(void);    /* libmbrt.a (libmbrt_float.a beside it) */
/* PREFIX/share/mbcc/NAME when mbcc runs installed and it exists, else NULL */
const char *mbcc_installed_file(const char *name);
#endif
