/* trade.h: `mbcc trade`, the speed/accuracy study of one model (trade.c), and
 * the two helpers of main.c that it shares with `mbcc run`. */
#ifndef MBCC_TRADE_H
#define MBCC_TRADE_H

/* mbcc trade M.yaml [options]: argv as given to mbcc (argv[1] is "trade").
 * Returns 0, 1 if the study could not be completed (e.g. the reference
 * failed), 2 on bad input. */
int cmd_trade(int argc, char **argv);

/* main.c: run argv[0] (PATH search), wait; its exit status, 128 if killed, -1
 * if it could not be started */
int run_command(char *const argv[]);
/* compile_generated: build.h */
#include "build.h"

#endif
