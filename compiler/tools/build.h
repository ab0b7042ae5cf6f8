/* build.h: the C build of a generated model (build.c): its sources, the
 * parallel compile, and the rebuild stamp that lets an unchanged model skip
 * it. */
#ifndef MBCC_BUILD_H
#define MBCC_BUILD_H

/* cc the generated model in DIR (NAME.c, or the files NAME.sources lists,
 * compiled in parallel) and the main program 'main_src' against the runtime
 * library (real_float: the single-precision one, libmbrt_float.a) into
 * 'exe'; 'extra' more arguments (NULL-terminated).  Not recompiled when
 * EXE.stamp holds the stamp of the same inputs. */
int compile_generated(const char *dir, const char *name, const char *main_src, const char *exe,
                      char *const extra[], int quiet, int real_float);
/* the same, built as 'exe' and then renamed to 'final_exe' (a name of this
 * process's own, so that two runs of one model never build over each other);
 * the stamp belongs to final_exe, so an unchanged model reuses it.
 * *reused: 1 when the compile was skipped (exe is then left alone). */
int compile_generated_into(const char *dir, const char *name, const char *main_src, const char *exe,
                           const char *final_exe, char *const extra[], int quiet, int real_float, int *reused);
/* the C files of the generated model NAME in DIR (paths, NULL-terminated, the
 * caller frees each and the array), or NULL out of memory */
char **generated_sources(const char *dir, const char *name);
/* how many compilers run at once: MBCC_JOBS, else the online CPUs */
int build_jobs(void);

#endif
