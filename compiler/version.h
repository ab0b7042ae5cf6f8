/* version.h: the one version number of mbcc (mbcc --version, the man page,
 * mbcc.pc). */
#ifndef MBCC_VERSION_H
#define MBCC_VERSION_H
#define MBCC_VERSION "0.9.0"
#endif
