/* test_bad_models.c: every malformed or inconsistent model in tests/bad_models/
 * gets its expected "file:line:col: error: ..." message and exit status 2 from
 * `mbcc check`, and `mbcc compile` writes nothing for it.  Each file states
 * what it expects in its first lines:
 *   # expect: <substring of the message>
 *   # expect-loc: LINE:COL          (optional; FILE:LINE:COL: in FILE, a file
 *                                    the model names, relative to its folder)
 *   # expect-note-loc: LINE:COL     (optional: a note at this place of the model)
 * Also: a redundant model compiles with a warning naming the joints. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "support.h"

static const char *mbcc(void) {
  const char *m = getenv("MBCC");
  return m && *m ? m : "build/mbcc";
}

static void copy(char *d, size_t n, const char *s) {
  size_t i = 0;
  for (; s[i] && i + 1 < n; i++) d[i] = s[i];
  d[i] = 0;
}

static void expectations(const char *path, char *msg, size_t n, char *loc, char *note_loc, size_t nl) {
  FILE *f = fopen(path, "r");
  char line[1024];
  msg[0] = loc[0] = note_loc[0] = 0;
  if (!f) return;
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\r\n")] = 0;
    if (!strncmp(line, "# expect: ", 10)) copy(msg, n, line + 10);
    else if (!strncmp(line, "# expect-loc: ", 14)) copy(loc, nl, line + 14);
    else if (!strncmp(line, "# expect-note-loc: ", 19)) copy(note_loc, nl, line + 19);
  }
  fclose(f);
}

static void check_bad_model(void **state) {
  const char *path = *state;
  char msg[512], loc[64], note_loc[64], cmd[2048], out[16384];
  expectations(path, msg, sizeof msg, loc, note_loc, sizeof loc);
  if (!msg[0]) {
    print_error("%s has no '# expect:' line\n", path);
    fail();
  }
  snprintf(cmd, sizeof cmd, "%s check '%s'", mbcc(), path);
  int rc = run_capture(cmd, out, sizeof out);
  if (rc != 2 || !strstr(out, msg)) {
    print_error("%s: exit %d (expected 2), output:\n%s(expected to contain: %s)\n", path, rc, out, msg);
    fail();
  }
  char where[1200];
  const char *slash = strrchr(path, '/');
  if (strchr(loc, ':') != strrchr(loc, ':')) /* FILE:LINE:COL, FILE in the model's folder */
    snprintf(where, sizeof where, "%.*s%s: error: ", slash ? (int)(slash - path + 1) : 0, path, loc);
  else
    snprintf(where, sizeof where, "%s:%s: error: ", path, loc);
  if (loc[0] && !strstr(out, where)) {
    print_error("%s: expected an error at %s, got:\n%s\n", path, loc, out);
    fail();
  }
  snprintf(where, sizeof where, "%s:%s: note: ", path, note_loc);
  if (note_loc[0] && !strstr(out, where)) {
    print_error("%s: expected a note at %s, got:\n%s\n", path, note_loc, out);
    fail();
  }
  if (!strstr(out, ": error: ")) {
    print_error("%s: no 'file:line:col: error:' diagnostic in:\n%s\n", path, out);
    fail();
  }
  /* nothing half-written: compile into a fresh directory must not create it */
  char dir[256];
  snprintf(dir, sizeof dir, "%s/badout_%d", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", (int)getpid());
  snprintf(cmd, sizeof cmd, "%s compile '%s' -o '%s'", mbcc(), path, dir);
  rc = run_capture(cmd, out, sizeof out);
  struct stat st;
  int exists = stat(dir, &st) == 0;
  if (exists) {
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    run_capture(cmd, out, sizeof out);
  }
  assert_int_equal(rc, 2);
  assert_false(exists);
}

static void test_redundant_warning(void **state) {
  (void)state;
  char cmd[1024], out[16384];
  snprintf(cmd, sizeof cmd, "%s check tests/models/four_bar_revolutes.yaml", mbcc());
  int rc = run_capture(cmd, out, sizeof out);
  if (rc != 0) print_error("%s", out);
  assert_int_equal(rc, 0);
  /* a planar loop of four revolute joints has 3 redundant rows in 3D */
  assert_non_null(strstr(out, "constraint rows   18 (3 redundant removed)"));
  assert_non_null(strstr(out, "degrees of freedom 0"));
  assert_non_null(strstr(out, "warning: redundant constraint removed: revolute 'rocker_pivot'"));
  assert_non_null(strstr(out, "combination of rows of revolute 'crank_pivot', revolute 'crank_pin', revolute 'rocker_pin'"));
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(void) {
  DIR *d = opendir("tests/bad_models");
  if (!d) { fprintf(stderr, "cannot open tests/bad_models\n"); return 1; }
  char *paths[256];
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) && n < 255) {
    size_t len = strlen(e->d_name);
    if (len < 6 || strcmp(e->d_name + len - 5, ".yaml")) continue;
    paths[n] = malloc(len + 32);
    snprintf(paths[n], len + 32, "tests/bad_models/%s", e->d_name);
    n++;
  }
  closedir(d);
  qsort(paths, (size_t)n, sizeof paths[0], by_name);
  struct CMUnitTest *tests = calloc((size_t)n + 1, sizeof *tests);
  for (int i = 0; i < n; i++) {
    tests[i].name = paths[i];
    tests[i].test_func = check_bad_model;
    tests[i].initial_state = paths[i];
  }
  tests[n].name = "redundant four-bar: warning, rows removed";
  tests[n].test_func = test_redundant_warning;
  int rc = _cmocka_run_group_tests("bad_models", tests, (size_t)n + 1, NULL, NULL);
  for (int i = 0; i < n; i++) free(paths[i]);
  free(tests);
  return rc;
}
