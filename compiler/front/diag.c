/* diag.c: see diag.h. */
#include "diag.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int error_count;
static int warning_count;
/* Notes follow the fate of the error or warning they explain. */
static bool last_message_hidden;

/* Warnings and notes already shown (hashes of the whole line): a model
 * assembled twice in one command, or several rows removed for one reason,
 * say each thing once. */
enum { SEEN_MAX = 512 };
static unsigned long long seen[SEEN_MAX];
static int nseen;

static unsigned long long line_hash(const char *s) {
  unsigned long long h = 1469598103934665603ull; /* FNV-1a */
  for (; *s; s++) h = (h ^ (unsigned char)*s) * 1099511628211ull;
  return h;
}

static bool muted;
void diag_mute(int on) { muted = on != 0; }
static char *registered[DIAG_MAX_FILES + 1];
static int nregistered;
/* per registered file: the subsystem instance it holds (NULL name: none) */
static struct {
  char *name, *prefix, *from_file;
  ir_loc from;
  int parent;
} instance[DIAG_MAX_FILES + 1];

static char *copy_text(const char *s) {
  size_t length = strlen(s);
  char *copy = malloc(length + 1);
  if (copy != NULL) memcpy(copy, s, length + 1);
  return copy;
}

int diag_register_instance(const char *path, const char *name, const char *prefix, ir_loc from,
                           const char *from_file) {
  if (nregistered == DIAG_MAX_FILES) return 0;
  char *copy = copy_text(path);
  if (copy == NULL) return 0;
  registered[++nregistered] = copy;
  int parent = from.line > 0 ? from.line / DIAG_FILE_LINES : 0;
  instance[nregistered].name = copy_text(name);
  instance[nregistered].prefix = copy_text(prefix);
  instance[nregistered].from_file = copy_text(diag_loc_file(from, from_file ? from_file : "mbcc"));
  instance[nregistered].from = diag_loc_in_file(from);
  instance[nregistered].parent = parent >= 1 && parent < nregistered && instance[parent].name ? parent : 0;
  return nregistered;
}

int diag_loc_instance(ir_loc loc) {
  int k = loc.line > 0 ? loc.line / DIAG_FILE_LINES : 0;
  return k >= 1 && k <= nregistered && instance[k].name ? k : 0;
}

const char *diag_instance_prefix(int k) {
  return k >= 1 && k <= nregistered && instance[k].prefix ? instance[k].prefix : "";
}

int diag_instance_parent(int k) { return k >= 1 && k <= nregistered ? instance[k].parent : 0; }

bool diag_check_lines(const char *path, const char *data, size_t size) {
  size_t lines = 1;
  for (size_t i = 0; i < size; i++) lines += data[i] == '\n';
  if (lines < DIAG_FILE_LINES) return true;
  diag_error(path, (ir_loc){0, 0}, "more than %d lines (the limit of the model reader)", DIAG_FILE_LINES - 1);
  return false;
}

int diag_register_file(const char *path) {
  for (int k = 1; k <= nregistered; k++)
    if (instance[k].name == NULL && strcmp(registered[k], path) == 0) return k;
  if (nregistered == DIAG_MAX_FILES) return 0;
  size_t length = strlen(path);
  char *copy = malloc(length + 1);
  if (copy == NULL) return 0;
  memcpy(copy, path, length + 1);
  registered[++nregistered] = copy;
  return nregistered;
}

const char *diag_loc_file(ir_loc loc, const char *file) {
  int k = loc.line > 0 ? loc.line / DIAG_FILE_LINES : 0;
  return k >= 1 && k <= nregistered ? registered[k] : file;
}

ir_loc diag_loc_in_file(ir_loc loc) {
  int k = loc.line > 0 ? loc.line / DIAG_FILE_LINES : 0;
  if (k >= 1 && k <= nregistered) loc.line -= k * DIAG_FILE_LINES;
  return loc;
}

static void print(const char *file, ir_loc loc, const char *severity,
                  const char *fmt, va_list ap) {
  if (muted) return;
  char line[2048];
  ir_loc loc_in = loc;
  file = diag_loc_file(loc, file);
  loc = diag_loc_in_file(loc);
  int n = snprintf(line, sizeof line, "%s", file == NULL ? "mbcc" : file);
  if (loc.line > 0 && n >= 0 && (size_t)n < sizeof line)
    n += snprintf(line + n, sizeof line - (size_t)n, ":%d:%d", loc.line, loc.col > 0 ? loc.col : 1);
  if (n >= 0 && (size_t)n < sizeof line)
    n += snprintf(line + n, sizeof line - (size_t)n, ": %s: ", severity);
  if (n >= 0 && (size_t)n < sizeof line)
    vsnprintf(line + n, sizeof line - (size_t)n, fmt, ap);
  if (severity[0] != 'e') {
    unsigned long long h = line_hash(line);
    for (int i = 0; i < nseen; i++)
      if (seen[i] == h) return;
    if (nseen < SEEN_MAX) seen[nseen++] = h;
  }
  fputs(line, stderr);
  fputc('\n', stderr);
  /* like a C compiler's "in expansion of": where the instance came from */
  for (int k = severity[0] == 'n' ? 0 : diag_loc_instance(loc_in); k != 0; k = instance[k].parent)
    fprintf(stderr, "%s:%d:%d: note: in the subsystem '%s' instantiated here\n", instance[k].from_file,
            instance[k].from.line, instance[k].from.col > 0 ? instance[k].from.col : 1, instance[k].name);
}

void diag_verror(const char *file, ir_loc loc, const char *fmt, va_list ap) {
  error_count++;
  last_message_hidden = error_count > DIAG_MAX_SHOWN_ERRORS;
  if (!last_message_hidden) {
    print(file, loc, "error", fmt, ap);
  } else if (error_count == DIAG_MAX_SHOWN_ERRORS + 1) {
    fprintf(stderr, "%s: note: too many errors; the remaining ones are not shown\n",
            file ? file : "mbcc");
  }
}

void diag_vwarning(const char *file, ir_loc loc, const char *fmt, va_list ap) {
  warning_count++;
  last_message_hidden = error_count > DIAG_MAX_SHOWN_ERRORS;
  if (!last_message_hidden)
    print(file, loc, "warning", fmt, ap);
}

void diag_vnote(const char *file, ir_loc loc, const char *fmt, va_list ap) {
  if (!last_message_hidden)
    print(file, loc, "note", fmt, ap);
}

void diag_error(const char *file, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_verror(file, loc, fmt, ap);
  va_end(ap);
}

void diag_warning(const char *file, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_vwarning(file, loc, fmt, ap);
  va_end(ap);
}

void diag_note(const char *file, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_vnote(file, loc, fmt, ap);
  va_end(ap);
}

int diag_errors(void) { return error_count; }
int diag_warnings(void) { return warning_count; }

void diag_reset(void) {
  error_count = 0;
  warning_count = 0;
  last_message_hidden = false;
  nseen = 0;
}
