/* emit_files.h: a large generated model as several translation units
 * (emit_files.c), so that the C compiler can build them in parallel and no
 * one file grows with the model.  Layout when the evaluation is in parts:
 *   <m>.c          tables, init, <m>_eval (calls the parts), the model record
 *   <m>_parts.h    private: the parts' shared struct and prototypes, and a
 *                  pointer to each table of <m>.c that set_params changes
 *                  and the parts read (the constant ones are copied)
 *   <m>_eval<k>.c  a group of evaluation parts
 *   <m>_ldl.c      the emitted LDL^T (factor and solve)
 *   <m>_ldl<k>.c   a straight-line LDL^T's out-of-line parts
 *   <m>.sources    the C files to compile, one a line (<m>.c first)
 * A model whose evaluation is in the loop form (one function in <m>.c) has
 * only the LDL^T's files, when its straight-line LDL^T is large.
 * A smaller model stays <m>.c alone, as before (no <m>.sources). */
#ifndef MBCC_EMIT_FILES_H
#define MBCC_EMIT_FILES_H

#include <stdio.h>

#include "emit_ldl.h"
#include "emit_split.h"

typedef struct {
  char name[320]; /* in the generated directory */
  FILE *f;        /* a memory stream while written */
  char *text;
  size_t len;
} gen_text;

/* a static of <m>.c copied into part files: kept in <m>.c by a pointer if
 * nothing else there reads it (emit_files_keep) */
typedef struct {
  char name[128];
  int kind;
  size_t from, to; /* its text in <m>.c */
  char *decl_head, *params;
} keep_decl;

typedef struct {
  const char *nm;
  long file_bytes;    /* evaluation text per file (0: one file) */
  int parts_per_file;
  gen_text header;    /* <m>_parts.h: what the split writes into it */
  gen_text refs;      /* <m>_parts.h: the table pointers' declarations */
  gen_text *eval;     /* <m>_eval<k>.c bodies */
  char **eval_macros; /* each one's table macros */
  int neval;
  gen_text ldl;       /* <m>_ldl.c body */
  gen_text **ldl_part; /* <m>_ldl<k>.c: the straight-line LDL^T's parts */
  int nldl_part;
  keep_decl *copied;
  int ncopied;
  int active;         /* the evaluation went into files */
  int has_ldl;         /* the LDL^T went into files (with or without the evaluation) */
  int failed;
  eval_files hooks;
} emit_files;

/* about this much evaluation text per file (MBCC_EVAL_FILE_BYTES overrides
 * it; 0: the model in one file) */
long eval_file_bytes(void);

void emit_files_init(emit_files *F, const char *nm);
/* the hooks for eval_split_finish, or NULL when the model stays one file */
const eval_files *emit_files_eval_hooks(emit_files *F);
/* after the evaluation: src is <m>.c's stream, 'text' its contents (the
 * tables the parts may read are declared in it).  Appends to src the pointer
 * to each table the parts read.  0, or -1 (a table the reader does not know
 * how to point at, out of memory: the caller writes one file instead) */
int emit_files_tables(emit_files *F, FILE *src, const char *text, size_t len);
/* at the end of <m>.c (its text so far in 'text'): a pointer to each static
 * copied into the parts that <m>.c itself does not read (no unused static) */
int emit_files_keep(emit_files *F, FILE *src, const char *text, size_t len);
/* the LDL^T in files of its own: returns the stream of <m>_ldl.c (NULL: out
 * of memory) and sets *out for emit_ldl: the wrappers the model record
 * points at to src, the straight-line code's parts to <m>_ldl0.c,
 * <m>_ldl1.c, ... of about file_bytes of text each */
FILE *emit_files_ldl(emit_files *F, FILE *src, ldl_out *out);
/* the text the LDL^T's files hold so far, in bytes (-1: out of memory) */
long emit_files_ldl_bytes(emit_files *F);
/* the extra files, each as its text after the origin comment: n of them
 * (the evaluation's when it is in files, the LDL^T's when it has files of its
 * own, the list) */
int emit_files_count(const emit_files *F);
/* file i: its name; its text (the caller frees it) after the comment line */
char *emit_files_text(emit_files *F, int i, const char **name, size_t *len);
void emit_files_free(emit_files *F);

/* the file names that DIR/<nm>.sources lists (written by an earlier
 * emission; names with a '/' are skipped), NULL-terminated, each allocated
 * (emit_files_list_free); NULL when there is no list or memory ran out */
char **emit_files_read_list(const char *dir, const char *nm);
void emit_files_list_free(char **names);

/* 1 if the identifier 'name' occurs in text (not in a comment, a string, or
 * as a member after '.' or '->') */
int c_text_names(const char *text, size_t len, const char *name);

#endif
