/* fuzz_front.c: the libFuzzer harness of the front end (make fuzz): a YAML
 * model -> IR (reader and its checks) -> flexible bodies (FE modes) ->
 * lowering (coordinates, rows, the sparse pattern) -> assembly analysis
 * (Newton on the constraints, redundancy) -> the LDL^T plan: the whole
 * pipeline of compiler/pipeline.c.  Every input must end in a result or located errors, within
 * the time and memory libFuzzer allows, with no sanitizer report.  The limits
 * are set low here (bodies, FE size) so that every run stays fast. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "diag.h"
#include "unit.h"

static char model_path[64];
static void remove_model(void) { unlink(model_path); }

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc; (void)argv;
  setenv("MBCC_MAX_BODIES", "40", 1);
  setenv("MBCC_MAX_FE_DOFS", "240", 1);
  setenv("MBCC_MAX_INPUT", "65536", 1);
  snprintf(model_path, sizeof model_path, "/tmp/mbcc-fuzz-%d.yaml", (int)getpid());
  atexit(remove_model);
  return 0;
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  FILE *f = fopen(model_path, "wb");
  if (!f) return 0;
  fwrite(data, 1, size, f);
  fclose(f);
  mbc_unit u;
  memset(&u, 0, sizeof u);
  mbc_unit_build(&u, model_path, NULL, 0);
  mbc_unit_free(&u);
  return 0;
}
