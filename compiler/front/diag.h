/* diag.h: GNU-style diagnostics ("file:line:col: error: message") on stderr,
 * with a process-wide error counter. */
#ifndef MBCC_DIAG_H
#define MBCC_DIAG_H

#include <stdarg.h>
#include <stddef.h>

#include "ir.h"

/* After this many errors further diagnostics are counted but not printed,
 * so one broken file cannot flood the terminal. */
#define DIAG_MAX_SHOWN_ERRORS 20

#if defined(__GNUC__) || defined(__clang__)
#define DIAG_PRINTF(fmt_index, first_arg) \
  __attribute__((format(printf, fmt_index, first_arg)))
#else
#define DIAG_PRINTF(fmt_index, first_arg)
#endif

/* 'file' may be NULL (the message is then prefixed "mbcc:"); a loc with
 * line <= 0 prints no line/column. */
void diag_error(const char *file, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
void diag_warning(const char *file, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
/* A note belongs to the preceding error or warning and is hidden with it. */
void diag_note(const char *file, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);

void diag_verror(const char *file, ir_loc loc, const char *fmt, va_list ap) DIAG_PRINTF(3, 0);
void diag_vwarning(const char *file, ir_loc loc, const char *fmt, va_list ap) DIAG_PRINTF(3, 0);
void diag_vnote(const char *file, ir_loc loc, const char *fmt, va_list ap) DIAG_PRINTF(3, 0);

/* Elements of included files (include:, subsystem instances) keep their file
 * in the line number: line = DIAG_FILE_LINES * k + line for the k-th
 * registered file, so that an ir_loc stays two ints.  Every file the reader
 * reads has fewer lines than DIAG_FILE_LINES (diag_check_lines); up to
 * DIAG_MAX_FILES files (k * DIAG_FILE_LINES stays below 2^31). */
#define DIAG_FILE_LINES (1 << 20)
#define DIAG_MAX_FILES 2000
/* false (after an error at 'path') when data has DIAG_FILE_LINES lines or more */
bool diag_check_lines(const char *path, const char *data, size_t size);
/* the number k of 'path' (registered once; a copy is kept), or 0 when the
 * table is full */
int diag_register_file(const char *path);
/* the file a location is in ('file' for the model's own lines), and the
 * location within that file */
const char *diag_loc_file(ir_loc loc, const char *file);
ir_loc diag_loc_in_file(ir_loc loc);

/* A subsystem instance (compose.c) is registered as a file of its own,
 * even when another instance reads the same file: its lines then carry the
 * instance, whose parameter names are looked up with 'prefix' first (then in
 * the enclosing instance 'parent', 0 for the model), and every message in
 * it is followed by a note "in the subsystem 'name' instantiated from
 * <from>".  Returns the number k as diag_register_file, or 0. */
int diag_register_instance(const char *path, const char *name, const char *prefix, ir_loc from,
                           const char *from_file);
/* the instance of a location's file (0: the model or an included file), its
 * full name prefix ("" for 0) and its enclosing instance */
int diag_loc_instance(ir_loc loc);
const char *diag_instance_prefix(int k);
int diag_instance_parent(int k);

int diag_errors(void);   /* errors reported so far (shown or not) */
int diag_warnings(void); /* warnings reported so far */
void diag_reset(void);
/* 1: count but print nothing (a second reading of the model that only probes
 * it, compiler/pipeline.c), 0: print again */
void diag_mute(int on);   /* zero both counters (e.g. between test cases) */

#endif
