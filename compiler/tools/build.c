/* build.c: the C build of a generated model: the files to compile (the
 * model's NAME.c, or the files NAME.sources lists for a model written as
 * several translation units, emit_files.h), compiled apart by up to one
 * compiler per CPU and linked; and the rebuild stamp, a content hash of what
 * goes into the executable, that lets an unchanged model skip the build. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "build.h"
#include "paths.h"
#include "proc.h"

/* --- the rebuild stamp: a content hash of what goes into an executable --- */

typedef struct { unsigned long long h; } build_hash;

static void hash_bytes(build_hash *b, const void *data, size_t n) {
  const unsigned char *p = data;
  for (size_t i = 0; i < n; i++) { b->h ^= p[i]; b->h *= 1099511628211ULL; } /* FNV-1a */
}

/* the file's name and contents (a missing file hashes as such) */
static void hash_file(build_hash *b, const char *path) {
  hash_bytes(b, path, strlen(path) + 1);
  FILE *f = fopen(path, "rb");
  if (!f) { hash_bytes(b, "(missing)", 10); return; }
  char buf[65536];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) hash_bytes(b, buf, n);
  fclose(f);
}

static int name_cmp(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* every .c and .h file of a folder, in name order */
static void hash_sources_in(build_hash *b, const char *dir) {
  DIR *d = opendir(dir);
  if (!d) { hash_bytes(b, dir, strlen(dir) + 1); return; }
  char *names[512];
  int nn = 0;
  for (struct dirent *e; (e = readdir(d)) && nn < 512;) {
    size_t len = strlen(e->d_name);
    if (len > 2 && e->d_name[len - 2] == '.' && (e->d_name[len - 1] == 'c' || e->d_name[len - 1] == 'h'))
      names[nn++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, (size_t)nn, sizeof names[0], name_cmp);
  for (int i = 0; i < nn; i++) {
    char path[8400];
    if (names[i]) {
      snprintf(path, sizeof path, "%s/%s", dir, names[i]);
      hash_file(b, path);
    }
    free(names[i]);
  }
}

/* exe's stamp: the compiler command, the generated sources, the runtime
 * headers and library -- an executable is reused only if all are unchanged */
static void build_stamp(char *out, size_t n, char *const ccargs[], const char *dir, const char *main_src,
                        const char *rtlib) {
  build_hash b = {14695981039346656037ULL};
  hash_bytes(&b, "mbcc build stamp 1", 19);
  /* the command of a one-file build (the files to compile and the flags,
     also when they are compiled apart and in parallel) */
  for (int i = 0; ccargs[i]; i++) {
    if (!strcmp(ccargs[i], "-o") && ccargs[i + 1]) { i++; continue; } /* a name of this process's own */
    hash_bytes(&b, ccargs[i], strlen(ccargs[i]) + 1);
  }
  hash_sources_in(&b, dir);
  hash_file(&b, main_src);
  /* the runtime headers: both include directories and the element kernels */
  char rt[8400];
  for (int k = 0; k < 2; k++) {
    const char *inc = mbcc_include_dir(k);
    if (!inc[0]) continue;
    hash_sources_in(&b, inc);
    snprintf(rt, sizeof rt, "%s/elements", inc);
    hash_sources_in(&b, rt);
  }
  hash_file(&b, rtlib);
  snprintf(out, n, "%016llx", b.h);
}

char **generated_sources(const char *dir, const char *name) {
  char path[8400], line[400];
  int cap = 16, n = 0;
  char **v = calloc((size_t)cap + 1, sizeof *v);
  if (!v) return NULL;
  snprintf(path, sizeof path, "%s/%s.sources", dir, name);
  FILE *f = fopen(path, "r");
  if (!f) { /* one file */
    snprintf(path, sizeof path, "%s/%s.c", dir, name);
    v[0] = strdup(path);
    if (!v[0]) { free(v); return NULL; }
    return v;
  }
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = 0;
    if (!line[0] || strchr(line, '/')) continue; /* names in DIR only */
    if (n == cap) {
      char **nv = realloc(v, sizeof *nv * (size_t)(2 * cap + 1));
      if (!nv) break;
      v = nv;
      cap *= 2;
    }
    snprintf(path, sizeof path, "%s/%s", dir, line);
    v[n] = strdup(path);
    if (!v[n]) break;
    v[++n] = NULL;
  }
  fclose(f);
  v[n] = NULL;
  return v;
}

int build_jobs(void) {
  const char *e = getenv("MBCC_JOBS");
  if (e && *e) {
    int j = atoi(e);
    if (j >= 1) return j;
  }
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n >= 1 ? (int)n : 1;
}

static void free_list(char **v) {
  for (int i = 0; v && v[i]; i++) free(v[i]);
  free(v);
}

/* compile each of srcs (and main_src) apart into objdir, up to build_jobs()
 * at once, then link them into exe: cc[0..ncc) are the compiler and its
 * flags, link[] what follows the objects (runtime, libraries).  0, or the
 * failing compiler's status. */
static int compile_parallel(char *const cc[], int ncc, char **srcs, const char *main_src, const char *exe,
                            char *const link[], const char *objdir) {
  int nsrc = 0;
  while (srcs[nsrc]) nsrc++;
  int nfile = nsrc + 1, rc = 0;
  char ***cmds = calloc((size_t)nfile, sizeof *cmds);
  char **objs = calloc((size_t)nfile, sizeof *objs);
  if (!cmds || !objs) { free(cmds); free(objs); return -1; }
  for (int i = 0; i < nfile && !rc; i++) {
    const char *src = i < nsrc ? srcs[i] : main_src;
    const char *base = strrchr(src, '/');
    base = base ? base + 1 : src;
    size_t ol = strlen(objdir) + strlen(base) + 16;
    objs[i] = malloc(ol);
    cmds[i] = calloc((size_t)ncc + 5, sizeof *cmds[i]);
    if (!objs[i] || !cmds[i]) { rc = -1; break; }
    snprintf(objs[i], ol, "%s/%d_%s.o", objdir, i, base); /* the index: two files of one name apart */
    int k = 0;
    for (int j = 0; j < ncc; j++) cmds[i][k++] = cc[j];
    cmds[i][k++] = "-c";
    cmds[i][k++] = (char *)src;
    cmds[i][k++] = "-o";
    cmds[i][k++] = objs[i];
    cmds[i][k] = NULL;
  }
  if (!rc) rc = proc_run_many(cmds, nfile, build_jobs());
  if (!rc) {
    int nl = 0;
    while (link[nl]) nl++;
    char **ld = calloc((size_t)(ncc + nfile + nl + 3), sizeof *ld);
    if (!ld) rc = -1;
    else {
      int k = 0;
      for (int j = 0; j < ncc; j++) ld[k++] = cc[j];
      ld[k++] = "-o";
      ld[k++] = (char *)exe;
      for (int i = 0; i < nfile; i++) ld[k++] = objs[i];
      for (int j = 0; j < nl; j++) ld[k++] = link[j];
      ld[k] = NULL;
      rc = proc_run(ld);
      free(ld);
    }
  }
  for (int i = 0; i < nfile; i++) {
    if (objs[i]) remove(objs[i]);
    free(objs[i]);
    free(cmds[i]);
  }
  free(objs);
  free(cmds);
  return rc;
}

int compile_generated_into(const char *dir, const char *name, const char *main_src, const char *exe,
                           const char *final_exe, char *const extra[], int quiet, int real_float, int *reused) {
  *reused = 0;
  char inc[8400], inc_hosted[8400], lib[8400];
  char **srcs = generated_sources(dir, name);
  if (!srcs) {
    fprintf(stderr, "mbcc: error: out of memory\n");
    return 2;
  }
  snprintf(inc, sizeof inc, "-I%s", mbcc_include_dir(0));
  snprintf(inc_hosted, sizeof inc_hosted, "-I%s", mbcc_include_dir(1)[0] ? mbcc_include_dir(1) : mbcc_include_dir(0));
  snprintf(lib, sizeof lib, "%s", mbcc_runtime_lib());
  if (real_float) {
    /* the single-precision runtime sits beside the double one: libmbrt_float.a */
    char *dot = strstr(lib, ".a");
    if (dot && !dot[2]) snprintf(dot, sizeof lib - (size_t)(dot - lib), "_float.a");
  }
  const char *cc = getenv("CC");
  /* the C flags mbcc itself was built with (e.g. sanitizers), split on spaces, but
     without debug information (-g), which doubles gcc's time on the large straight-line
     files; MBCC_CFLAGS, when set, replaces them (MBCC_CFLAGS="-O2 -g" to debug a model) */
  static char flags[1024];
  const char *user_flags = getenv("MBCC_CFLAGS");
  snprintf(flags, sizeof flags, "%s", user_flags ? user_flags : MBCC_GEN_CFLAGS);
  int keep_debug_info = user_flags != NULL;
  int nsrc = 0;
  while (srcs[nsrc]) nsrc++;
  char **ccargs = calloc((size_t)nsrc + 100, sizeof *ccargs);
  if (!ccargs) {
    free_list(srcs);
    fprintf(stderr, "mbcc: error: out of memory\n");
    return 2;
  }
  int nc = 0;
  ccargs[nc++] = (char *)(cc && *cc ? cc : "cc");
  ccargs[nc++] = "-std=c99";
  /* no contraction into fused multiply-adds (clang's default): the generated code gives
     the generic path's numbers to the last bit, whatever the flags or the compiler */
  ccargs[nc++] = "-ffp-contract=off";
  if (real_float) ccargs[nc++] = "-DMB_REAL_FLOAT";
  for (char *tok = strtok(flags, " "); tok && nc < 40; tok = strtok(NULL, " "))
    if (keep_debug_info || strncmp(tok, "-g", 2) != 0) ccargs[nc++] = tok;
  ccargs[nc++] = inc;
  ccargs[nc++] = inc_hosted;
  int nflags = nc; /* the compiler and its flags */
  ccargs[nc++] = "-o";
  ccargs[nc++] = (char *)exe;
  for (int i = 0; i < nsrc; i++) ccargs[nc++] = srcs[i];
  ccargs[nc++] = (char *)main_src;
  int link_from = nc; /* the runtime and the libraries */
  ccargs[nc++] = lib;
  for (int i = 0; extra && extra[i] && i < 20; i++) ccargs[nc++] = extra[i];
  char *libs[] = {"-lklu", "-lamd", "-lcolamd", "-lbtf", "-lsuitesparseconfig", "-llapack",
                  "-lblas", "-lm", NULL};
  for (int i = 0; libs[i]; i++) ccargs[nc++] = libs[i];
  ccargs[nc] = NULL;
  char stamp[32], stamp_path[8500], old[32] = "";
  build_stamp(stamp, sizeof stamp, ccargs, dir, main_src, lib);
  snprintf(stamp_path, sizeof stamp_path, "%s.stamp", final_exe);
  FILE *sf = fopen(stamp_path, "r");
  if (sf) {
    if (!fgets(old, sizeof old, sf)) old[0] = 0;
    fclose(sf);
    old[strcspn(old, "\n")] = 0;
  }
  if (!strcmp(old, stamp) && access(final_exe, X_OK) == 0) {
    if (!quiet)
      fprintf(stderr, "mbcc: %s is up to date (same generated code, compiler, flags and runtime)\n", final_exe);
    *reused = 1;
    free(ccargs);
    free_list(srcs);
    return 0;
  }
  int rc;
  if (nsrc == 1) { /* one file: one command, as it always was */
    if (!quiet) fprintf(stderr, "mbcc: compiling %s\n", srcs[0]);
    rc = proc_run(ccargs);
  } else {
    /* the objects in a directory of this build's own, removed after */
    char objdir[8500];
    snprintf(objdir, sizeof objdir, "%s.objs", exe);
    if (!quiet)
      fprintf(stderr, "mbcc: compiling %s/%s (%d files, %d at a time)\n", dir, name, nsrc + 1, build_jobs());
    if (mkdir(objdir, 0777) && errno != EEXIST) {
      fprintf(stderr, "mbcc: error: cannot create '%s': %s\n", objdir, strerror(errno));
      rc = 2;
    } else {
      proc_cleanup_add(objdir);
      rc = compile_parallel(ccargs, nflags, srcs, main_src, exe, ccargs + link_from, objdir);
      proc_remove_temporary(objdir);
      proc_cleanup_remove(objdir);
    }
  }
  if (rc) {
    fprintf(stderr, "mbcc: error: the C compiler failed on %s\n", nsrc == 1 ? srcs[0] : dir);
    free(ccargs);
    free_list(srcs);
    return 2;
  }
  free(ccargs);
  free_list(srcs);
  /* the old stamp goes first: for a moment there is an executable without
     one (rebuilt next time), never one with another's stamp */
  remove(stamp_path);
  if (strcmp(exe, final_exe) && rename(exe, final_exe)) {
    fprintf(stderr, "mbcc: error: cannot write '%s': %s\n", final_exe, strerror(errno));
    return 2;
  }
  char stamp_part[8520];
  snprintf(stamp_part, sizeof stamp_part, "%s.XXXXXX", stamp_path);
  int sfd = mkstemp(stamp_part);
  sf = sfd >= 0 ? fdopen(sfd, "w") : NULL;
  if (sf) {
    fprintf(sf, "%s\n", stamp);
    int bad = ferror(sf);
    if (fclose(sf) || bad || rename(stamp_part, stamp_path)) remove(stamp_part);
  } else if (sfd >= 0) {
    close(sfd);
    remove(stamp_part);
  }
  return 0;
}

int compile_generated(const char *dir, const char *name, const char *main_src, const char *exe,
                      char *const extra[], int quiet, int real_float) {
  int reused;
  return compile_generated_into(dir, name, main_src, exe, exe, extra, quiet, real_float, &reused);
}
