/* plot.h: mbcc plot: CSV results drawn with gnuplot. */
#ifndef MBCC_PLOT_H
#define MBCC_PLOT_H

/* Plot the columns of the CSV files csv[0..ncsv-1] against their first
 * column (time) into png: one panel per entry of 'columns' ("a,b+c": a, then
 * b and c together; NULL: every column), the same columns of every file
 * overlaid, 8 panels a page (png, then png-2.png, ...).  A column whose
 * variation is round-off is drawn flat and labelled so; units come from
 * CSV.units when it exists.  Prints "wrote FILE" per page unless quiet.
 * 0, or 2 after an error message (unknown column: the known ones listed). */
/* A results CSV that can be read whole: a regular file (not a device or a
 * pipe, which could stream forever: /dev/zero) of at most 1 GiB
 * (MBCC_MAX_CSV=BYTES lifts it).  0, or 2 after reporting. */
int csv_file_check(const char *path);

int plot_files(int ncsv, const char *const *csv, const char *png, const char *columns, int quiet);
/* keep the gnuplot script at this path (mbcc plot --gnuplot FILE), or NULL */
extern const char *plot_keep_script;
#endif
