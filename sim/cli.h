/* SPDX-License-Identifier: ISC */
/* What every program's command line shares (sim tools and daemon programs
 * alike; daemon/ may include sim/ headers):
 *   -h, --help     usage on standard output, exit 0
 *   -V, --version  "PROGRAM (psensd) VERSION" on standard output, exit 0
 * and the warning an old spelling gives for one release.  The letters'
 * meanings across the programs are in doc/commands.md. */
#ifndef PS_CLI_H
#define PS_CLI_H

#include <getopt.h>
#include <stdio.h>

/* the two long options, for a getopt_long table */
#define PS_CLI_LONGOPTS { "help", no_argument, NULL, 'h' }, { "version", no_argument, NULL, 'V' }

/* print the version line; returns 0 (the exit status) */
int ps_cli_version(const char *prog);

/* "PROG: warning: OLD is deprecated and goes in the next release; use NEW" on stderr */
void ps_cli_deprecated(const char *prog, const char *old, const char *now);

/* 1 when s is a whole real number (an old numeric argument), 0 else */
int ps_cli_is_number(const char *s);

#endif
