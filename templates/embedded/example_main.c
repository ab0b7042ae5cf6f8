/* example_main.c: the @MODEL@ model in a fixed-rate loop, as firmware runs it.
 * On a board, call @MODEL@_step from the timer interrupt (or an RTOS task)
 * every @UMODEL@_STEP seconds; here the loop runs 1000 steps and stops. */
#include "@MODEL@_api.h"

static @MODEL@_data data;            /* all the model's state: @UMODEL@_DATA_BYTES bytes */
static mb_real y[@UMODEL@_NOUTPUT + 1]; /* outputs, named in @MODEL@_output_names */
volatile mb_real sink;                /* keeps the outputs observable */

int main(void) {
  int st = @MODEL@_init(&data);
  if (st) return st;
  for (int k = 0; k < 1000; k++) {
    /* inputs first (for k in 0..@UMODEL@_NINPUT-1): @MODEL@_set_input(&data, k, value); */
    st = @MODEL@_step(&data, (mb_real)@UMODEL@_STEP);
    if (st) return st; /* an mb_status: MB_ERR_SINGULAR, MB_ERR_NONFINITE, MB_ERR_PROJECTION */
    st = @MODEL@_outputs(&data, y);
    if (st) return st;
    for (int c = 0; c < @UMODEL@_NOUTPUT; c++) sink = y[c]; /* e.g. to a DAC or a CAN frame */
  }
  return 0;
}
