/* help.h: the command line's help text, one source for `mbcc help`,
 * `mbcc CMD --help` and the man page (mbcc help --man > docs/mbcc.1). */
#ifndef MBCC_HELP_H
#define MBCC_HELP_H
#include <stdio.h>

/* the overview (cmd NULL) or one command's help on f; -1 for an unknown command */
int help_print(FILE *f, const char *cmd);
/* the short usage lines of every command, for errors */
void help_usage(FILE *f);
/* the man page, troff -man, on f */
void help_man(FILE *f);
#endif
