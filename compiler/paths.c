/* paths.c: see paths.h.  In this order:
 *   1. MBCC_ROOT in the environment: a source tree (ROOT/templates,
 *      ROOT/runtime/{core,hosted}); the library MBCC_RTLIB, else the one
 *      this mbcc was built with;
 *   2. installed: the executable in PREFIX/bin with PREFIX/share/mbcc/templates,
 *      PREFIX/include/mbcc and PREFIX/lib/libmbrt.a;
 *   3. a build tree: the executable in ROOT/B with ROOT/templates and the
 *      library in ROOT/B (so build/ and build-clang/ each use their own);
 *   4. the tree this mbcc was compiled in (MBCC_ROOT, MBCC_RTLIB).
 * MBCC_RTLIB in the environment overrides the library in every case. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "paths.h"

#ifndef MBCC_ROOT
#define MBCC_ROOT "."
#endif
#ifndef MBCC_RTLIB
#define MBCC_RTLIB MBCC_ROOT "/build/libmbrt.a"
#endif

static char templates[4200], include[2][4200], lib[4200], share[4200];
static int found;

static int exists(const char *dir, const char *file) {
  char p[8500];
  snprintf(p, sizeof p, "%s/%s", dir, file);
  return access(p, R_OK) == 0;
}

static void source_tree(const char *root, const char *rtlib) {
  snprintf(templates, sizeof templates, "%s/templates", root);
  snprintf(include[0], sizeof include[0], "%s/runtime/core", root);
  snprintf(include[1], sizeof include[1], "%s/runtime/hosted", root);
  snprintf(lib, sizeof lib, "%s", rtlib);
}

static void locate(void) {
  if (found) return;
  found = 1;
  const char *root = getenv("MBCC_ROOT");
  char exe[2048] = "";
  ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  exe[n > 0 ? n : 0] = 0;
  char *slash = strrchr(exe, '/');
  if (slash) *slash = 0; /* the executable's directory */
  char up[2100], dotdot[2100];
  snprintf(dotdot, sizeof dotdot, "%s/..", exe);
  char *real = realpath(dotdot, NULL); /* PREFIX, not PREFIX/bin/.. */
  snprintf(up, sizeof up, "%s", real ? real : dotdot);
  free(real);
  if (root && *root) {
    source_tree(root, MBCC_RTLIB);
  } else if (slash && exists(up, "share/mbcc/templates/main.c.in")) {
    snprintf(templates, sizeof templates, "%s/share/mbcc/templates", up);
    snprintf(share, sizeof share, "%s/share/mbcc", up);
    snprintf(include[0], sizeof include[0], "%s/include/mbcc", up);
    include[1][0] = 0;
    snprintf(lib, sizeof lib, "%s/lib/libmbrt.a", up);
  } else if (slash && exists(up, "templates/main.c.in") && exists(exe, "libmbrt.a")) {
    char rtlib[2100];
    snprintf(rtlib, sizeof rtlib, "%s/libmbrt.a", exe);
    source_tree(up, rtlib);
  } else {
    source_tree(MBCC_ROOT, MBCC_RTLIB);
  }
  const char *rtlib = getenv("MBCC_RTLIB");
  if (rtlib && *rtlib) snprintf(lib, sizeof lib, "%s", rtlib);
}

const char *mbcc_templates_dir(void) { locate(); return templates; }
const char *mbcc_include_dir(int k) { locate(); return include[k ? 1 : 0]; }
const char *mbcc_runtime_lib(void) { locate(); return lib; }

const char *mbcc_installed_file(const char *name) {
  static char path[4300];
  locate();
  if (!share[0] || !exists(share, name)) return NULL;
  snprintf(path, sizeof path, "%s/%s", share, name);
  return path;
}
