/* verify_main.c: runs @MODEL@ for VERIFY_STEPS steps of @UMODEL@_STEP and writes,
 * every VERIFY_EVERY steps, the time and the outputs as the hex of their bits
 * (no printf: the float build links no double arithmetic).  The same file
 * runs on the host (-DMB_HOST) and under qemu, and the two logs are compared. */
#include "@MODEL@_api.h"

#ifndef VERIFY_STEPS
#define VERIFY_STEPS 200
#endif
#ifndef VERIFY_EVERY
#define VERIFY_EVERY 20
#endif

/* an input schedule (models with inputs): input VERIFY_INPUT is set to
 * VERIFY_INPUT_FIRST before the first step and to VERIFY_INPUT_THEN before
 * step VERIFY_INPUT_AT */
#ifdef VERIFY_INPUT
#ifndef VERIFY_INPUT_AT
#define VERIFY_INPUT_AT VERIFY_STEPS
#define VERIFY_INPUT_THEN 0
#endif
#endif

#ifdef MB_HOST
#include <stdio.h>
static void emb_write(const char *s) { fputs(s, stdout); }
#else
void emb_write(const char *s);
#endif

static @MODEL@_data data;

static void put_real(mb_real x) {
  unsigned char b[sizeof x];
  char txt[2 * sizeof x + 2];
  const unsigned char *p = (const unsigned char *)&x;
  for (unsigned i = 0; i < sizeof x; i++) b[i] = p[sizeof x - 1 - i]; /* little-endian: high byte first */
  for (unsigned i = 0; i < sizeof x; i++) {
    txt[2 * i] = "0123456789abcdef"[b[i] >> 4];
    txt[2 * i + 1] = "0123456789abcdef"[b[i] & 15];
  }
  txt[2 * sizeof x] = ' ';
  txt[2 * sizeof x + 1] = 0;
  emb_write(txt);
}

int main(void) {
  static mb_real y[@UMODEL@_NOUTPUT + 1];
  int st = @MODEL@_init(&data);
  for (int k = 0; !st && k <= VERIFY_STEPS; k++) {
#ifdef VERIFY_INPUT
    if (!st && k == 0) st = @MODEL@_set_input(&data, VERIFY_INPUT, (mb_real)VERIFY_INPUT_FIRST);
    if (!st && k == VERIFY_INPUT_AT) st = @MODEL@_set_input(&data, VERIFY_INPUT, (mb_real)VERIFY_INPUT_THEN);
#endif
    if (!st && k % VERIFY_EVERY == 0) {
      st = @MODEL@_outputs(&data, y);
      put_real(@MODEL@_time(&data));
      for (int c = 0; c < @UMODEL@_NOUTPUT; c++) put_real(y[c]);
      emb_write("\n");
    }
    if (!st && k < VERIFY_STEPS) st = @MODEL@_step(&data, (mb_real)@UMODEL@_STEP);
  }
  emb_write(st ? "status error\n" : "status ok\n");
  return st;
}
