/* proc.h: running child programs (the C compiler, the simulator, gnuplot)
 * so that they die with mbcc, and files that must not be half-written. */
#ifndef MBCC_PROC_H
#define MBCC_PROC_H

/* Run argv and wait for it: its exit status, 128 + its signal, or -1.  The
 * child stays in mbcc's process group (a ^C reaches both); a SIGINT, SIGTERM
 * or SIGHUP sent to mbcc alone is passed on to it, and once it is reaped mbcc
 * removes the registered temporary files and dies of the same signal.  On
 * Linux the child also gets SIGTERM if mbcc is killed outright. */
int proc_run(char *const argv[]);
/* the same, calling tick(user) about four times a second while the child runs */
int proc_run_watch(char *const argv[], void (*tick)(void *), void *user);

/* Run the n commands argvs[i], at most 'jobs' at a time, and wait for all:
 * 0, or the first nonzero status (no command is started after a failure).
 * Signals as for proc_run, passed on to every running child. */
int proc_run_many(char **const argvs[], int n, int jobs);

/* Temporary files (or directories of files) removed if mbcc is killed while
 * a child runs (at most 8). */
void proc_cleanup_add(const char *path);
void proc_cleanup_remove(const char *path);
/* remove a file, or a directory and the files in it */
void proc_remove_temporary(const char *path);

/* 1 if both paths name one existing file (same device and inode) */
int proc_same_file(const char *a, const char *b);

#endif
