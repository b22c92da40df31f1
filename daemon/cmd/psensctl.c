/* psensctl: talk to psensd.  This version reads the sample log directly
 * (readable while psensd writes it):
 *   psensctl -d DATABASE export --csv
 * See psensctl(1). */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "db.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psensctl -d database export --csv\n");
}

int main(int argc, char **argv)
{
	const char *dbpath = NULL;
	char err[512];
	int opt;
	while ((opt = getopt(argc, argv, "+d:h")) != -1) {
		switch (opt) {
		case 'd': dbpath = optarg; break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (!dbpath || optind + 2 != argc || strcmp(argv[optind], "export") != 0 ||
	    strcmp(argv[optind + 1], "--csv") != 0) {
		usage(stderr);
		return 2;
	}
	if (psd_db_export_csv(dbpath, stdout, err, sizeof err) != 0) {
		fprintf(stderr, "psensctl: %s\n", err);
		return 1;
	}
	return fflush(stdout) == 0 ? 0 : 1;
}
