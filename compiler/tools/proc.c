/* proc.c: children that die with mbcc; see proc.h. */
#define _GNU_SOURCE
#include "proc.h"

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

static void pass_on(int sig) {
  received = sig;
  if (running > 0) kill(running, sig);
}

int proc_run(char *const argv[]) { return proc_run_watch(argv, NULL, NULL); }

int proc_run_watch(char *const argv[], void (*tick)(void *), void *user) {
  fflush(stdout);
  fflush(stderr);
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction sa, old[3];
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = pass_on;
  sigemptyset(&sa.sa_mask);
  /* block the signals over the fork, so that none falls between the child's
     creation and 'running' naming it */
  sigset_t block, saved;
  sigemptyset(&block);
  for (int i = 0; i < 3; i++) sigaddset(&block, sigs[i]);
  sigprocmask(SIG_BLOCK, &block, &saved);
  for (int i = 0; i < 3; i++) sigaction(sigs[i], &sa, &old[i]);
  pid_t parent = getpid();
  pid_t pid = fork();
  if (pid == 0) {
    for (int i = 0; i < 3; i++) sigaction(sigs[i], &old[i], NULL);
    sigprocmask(SIG_SETMASK, &saved, NULL);
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
      if (cleanup[i][0]) unlink(cleanup[i]);
    signal(received, SIG_DFL);
    raise(received);
  }
  return rc;
}
