/* proc.c: children that die with mbcc; see proc.h. */
#define _GNU_SOURCE
#include "proc.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

static char cleanup[8][4200];
static volatile sig_atomic_t received; /* the signal mbcc got while a child ran */
static volatile pid_t running;         /* that child */

void proc_cleanup_add(const char *path) {
  for (int i = 0; i < 8; i++)
    if (!cleanup[i][0]) { snprintf(cleanup[i], sizeof cleanup[i], "%s", path); return; }
}

void proc_cleanup_remove(const char *path) {
  for (int i = 0; i < 8; i++)
    if (!strcmp(cleanup[i], path)) cleanup[i][0] = 0;
}

int proc_same_file(const char *a, const char *b) {
  struct stat sa, sb;
  return a && b && !stat(a, &sa) && !stat(b, &sb) && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* the children of proc_run_many, while they run */
#define MAX_JOBS 64
static volatile pid_t running_many[MAX_JOBS];

/* a registered temporary: a file, or a directory of files (objects) */
static void remove_temporary(const char *path) {
  if (!unlink(path) || errno == ENOENT) return;
  DIR *d = opendir(path);
  if (!d) return;
  char p[4400];
  for (struct dirent *e; (e = readdir(d));) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    snprintf(p, sizeof p, "%s/%s", path, e->d_name);
    unlink(p);
  }
  closedir(d);
  rmdir(path);
}

void proc_remove_temporary(const char *path) { remove_temporary(path); }

static void pass_on(int sig) {
  received = sig;
  if (running > 0) kill(running, sig);
  for (int i = 0; i < MAX_JOBS; i++)
    if (running_many[i] > 0) kill(running_many[i], sig);
}

/* SIGINT, SIGTERM and SIGHUP passed on to the children (pass_on), with the
 * three blocked until the caller unblocks them (saved): none may fall between
 * a child's creation and 'running' naming it.  old: the actions to restore;
 * block: the three */
static void catch_signals(struct sigaction old[3], sigset_t *saved, sigset_t *block) {
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = pass_on;
  sigemptyset(&sa.sa_mask);
  sigemptyset(block);
  for (int i = 0; i < 3; i++) sigaddset(block, sigs[i]);
  sigprocmask(SIG_BLOCK, block, saved);
  for (int i = 0; i < 3; i++) sigaction(sigs[i], &sa, &old[i]);
}

/* the child's side of a fork: the caller's signal actions and mask back,
 * death with mbcc, then argv */
static _Noreturn void exec_child(char *const argv[], const struct sigaction old[3], const sigset_t *saved, pid_t parent) {
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  for (int i = 0; i < 3; i++) sigaction(sigs[i], &old[i], NULL);
  sigprocmask(SIG_SETMASK, saved, NULL);
#ifdef __linux__
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(128 + SIGTERM); /* mbcc died before prctl */
#else
  (void)parent;
#endif
  execvp(argv[0], argv);
  fprintf(stderr, "mbcc: error: cannot run '%s': %s\n", argv[0], strerror(errno));
  _exit(127);
}

int proc_run(char *const argv[]) { return proc_run_watch(argv, NULL, NULL); }

int proc_run_watch(char *const argv[], void (*tick)(void *), void *user) {
  fflush(stdout);
  fflush(stderr);
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction old[3];
  sigset_t saved, block;
  catch_signals(old, &saved, &block);
  pid_t parent = getpid();
  pid_t pid = fork();
  if (pid == 0) exec_child(argv, old, &saved, parent);
  running = pid;
  sigprocmask(SIG_SETMASK, &saved, NULL);
  int status = 0, rc;
  if (pid < 0) rc = -1;
  else {
    if (tick) {
      /* poll, calling tick about four times a second until the child ends */
      for (;;) {
        pid_t w = waitpid(pid, &status, WNOHANG);
        if (w == pid || (w < 0 && errno != EINTR)) break;
        tick(user);
        struct timespec ts = {0, 250000000L};
        nanosleep(&ts, NULL);
      }
    } else
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    rc = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 128;
  }
  running = 0;
  for (int i = 0; i < 3; i++) sigaction(sigs[i], &old[i], NULL);
  if (received) {
    /* the child is reaped: leave no temporary file, and die as told */
    for (int i = 0; i < 8; i++)
      if (cleanup[i][0]) remove_temporary(cleanup[i]);
    signal(received, SIG_DFL);
    raise(received);
  }
  return rc;
}

int proc_run_many(char **const argvs[], int n, int jobs) {
  fflush(stdout);
  fflush(stderr);
  if (jobs < 1) jobs = 1;
  if (jobs > MAX_JOBS) jobs = MAX_JOBS;
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction old[3];
  sigset_t saved, block;
  catch_signals(old, &saved, &block);
  pid_t parent = getpid();
  int next = 0, active = 0, rc = 0;
  while (next < n || active > 0) {
    /* start children up to 'jobs' (none after a failure: wait for the rest) */
    while (next < n && active < jobs && !rc && !received) {
      pid_t pid = fork();
      if (pid == 0) exec_child(argvs[next], old, &saved, parent);
      if (pid < 0) { rc = -1; break; }
      for (int i = 0; i < MAX_JOBS; i++)
        if (running_many[i] <= 0) { running_many[i] = pid; break; }
      active++;
      next++;
    }
    if (active == 0) break;
    /* wait with the signals let through, so that one is passed on at once */
    sigprocmask(SIG_SETMASK, &saved, NULL);
    int status = 0;
    pid_t w = waitpid(-1, &status, 0);
    sigprocmask(SIG_BLOCK, &block, NULL);
    if (w < 0) {
      if (errno == EINTR) continue;
      rc = rc ? rc : -1;
      break;
    }
    for (int i = 0; i < MAX_JOBS; i++)
      if (running_many[i] == w) {
        running_many[i] = 0;
        active--;
        int st = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 128;
        if (st && !rc) rc = st;
      }
  }
  for (int i = 0; i < MAX_JOBS; i++) running_many[i] = 0;
  for (int i = 0; i < 3; i++) sigaction(sigs[i], &old[i], NULL);
  sigprocmask(SIG_SETMASK, &saved, NULL);
  if (received) {
    for (int i = 0; i < 8; i++)
      if (cleanup[i][0]) remove_temporary(cleanup[i]);
    signal(received, SIG_DFL);
    raise(received);
  }
  return rc;
}
