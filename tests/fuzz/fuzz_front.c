/* fuzz_front.c: the libFuzzer harness of the front end (make fuzz): a YAML
 * model -> IR (reader and its checks) -> flexible bodies (FE modes) ->
 * lowering (coordinates, rows, the sparse pattern) -> assembly analysis
 * (Newton on the constraints, redundancy) -> the LDL^T plan: the whole
 * pipeline of compiler/pipeline.c.  Every input must end in a result or located errors, within
 * the time and memory libFuzzer allows, with no sanitizer report.  The limits
 * are set low here (bodies, FE size) so that every run stays fast.  An input
 * that names the modal data file's format ("format: mbcc-modal", as the
 * seeds in tests/bad_models/modal/ do) is fuzzed as the modal data file of a
 * fixed model's flexible body instead. */
#define _GNU_SOURCE
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "diag.h"
#include "unit.h"

static char model_path[64], modal_path[64], modal_model_path[64];
static void remove_model(void) {
  unlink(model_path);
  unlink(modal_path);
  unlink(modal_model_path);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc; (void)argv;
  setenv("MBCC_MAX_BODIES", "40", 1);
  setenv("MBCC_MAX_FE_DOFS", "240", 1);
  setenv("MBCC_MAX_INPUT", "65536", 1);
  snprintf(model_path, sizeof model_path, "/tmp/mbcc-fuzz-%d.yaml", (int)getpid());
  snprintf(modal_path, sizeof modal_path, "/tmp/mbcc-fuzz-%d.modal", (int)getpid());
  snprintf(modal_model_path, sizeof modal_model_path, "/tmp/mbcc-fuzz-%d-modal.yaml", (int)getpid());
  /* the model whose flexible body reads the fuzzed modal data file */
  FILE *f = fopen(modal_model_path, "w");
  if (f) {
    fprintf(f, "name: fuzz_modal\nbodies:\n  rod:\n    type: flexible\n    modes: all\n"
               "    modal_file: %s\n", modal_path + 5);
    fclose(f);
  }
  atexit(remove_model);
  return 0;
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static const char modal_format[] = "format: mbcc-modal";
  bool modal = memmem(data, size, modal_format, sizeof modal_format - 1) != NULL;
  FILE *f = fopen(modal ? modal_path : model_path, "wb");
  if (!f) return 0;
  fwrite(data, 1, size, f);
  fclose(f);
  mbc_unit u;
  memset(&u, 0, sizeof u);
  mbc_unit_build(&u, modal ? modal_model_path : model_path, NULL, 0);
  mbc_unit_free(&u);
  return 0;
}
