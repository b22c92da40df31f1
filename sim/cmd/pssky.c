/* SPDX-License-Identifier: ISC */
/* pssky: a sky matrix from a weather file, as Radiance's gendaymtx makes it:
 * the Perez all-weather sky on the Tregenza / Reinhart patches and the
 * ground, one column per time step, in Radiance's matrix format.
 *   pssky [-v][-H][-A][-d|-s][-u][-r deg][-m N][-g r g b][-c r g b]
 *         [-5 size][-o{a|f|d}][-O{0|1}][-e][-E] [weather.wea|weather.epw]
 * Reads standard input without a file.  Everything is computed before the
 * first byte is written: a bad input line gives file:line and no output.
 * See pssky(1). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "fileio.h"
#include "mtx.h"
#include "patches.h"
#include "sky.h"
#include "weather.h"

#define DEG (M_PI / 180.0)

static void usage(FILE *fp)
{
	fprintf(fp, "usage: pssky [-v][-H][-A][-d|-s][-u][-r deg][-m N][-g r g b][-c r g b]"
	            "[-5 size][-o{a|f|d}][-O{0|1}][-e][-E] [weather.wea|weather.epw]\n"
	            "  gendaymtx's options (see pssky(1)); -H is gendaymtx's -h (no header)\n"
	            "  -h, --help  this help;  -V, --version  the version\n");
}

/* A number argument, or exit 2 naming the option. */
static double number(int argc, char **argv, int *i, const char *opt)
{
	char *end;
	double x;
	if (*i + 1 >= argc) {
		fprintf(stderr, "pssky: %s needs a number\n", opt);
		exit(2);
	}
	errno = 0;
	x = strtod(argv[++*i], &end);
	if (end == argv[*i] || *end || !isfinite(x) || errno == ERANGE) {
		fprintf(stderr, "pssky: %s: '%s' is not a number\n", opt, argv[*i]);
		exit(2);
	}
	return x;
}

static void triple(int argc, char **argv, int *i, const char *opt, double v[3])
{
	for (int k = 0; k < 3; k++) {
		v[k] = number(argc, argv, i, opt);
		if (v[k] < 0) {
			fprintf(stderr, "pssky: %s: %g is negative\n", opt, v[k]);
			exit(2);
		}
	}
}

/* stdin into memory */
static int read_stdin(uint8_t **data, size_t *len, struct ps_err *e)
{
	size_t cap = 65536, n = 0;
	uint8_t *buf = malloc(cap);
	if (!buf)
		return ps_err_set(e, PS_ENOMEM, "(stdin): out of memory");
	for (;;) {
		size_t got;
		if (n + 1 >= cap) {
			uint8_t *nb;
			if (cap > PS_WX_MAX_FILE) {
				free(buf);
				return ps_err_set(e, PS_ERANGE, "(stdin): larger than %u bytes", PS_WX_MAX_FILE);
			}
			nb = realloc(buf, cap * 2);
			if (!nb) {
				free(buf);
				return ps_err_set(e, PS_ENOMEM, "(stdin): out of memory");
			}
			buf = nb;
			cap *= 2;
		}
		got = fread(buf + n, 1, cap - n - 1, stdin);
		n += got;
		if (got == 0)
			break;
	}
	if (ferror(stdin)) {
		free(buf);
		return ps_err_sys(e, "(stdin): read error");
	}
	buf[n] = '\0';
	*data = buf;
	*len = n;
	return 0;
}

int main(int argc, char **argv)
{
	struct ps_sky_opt o;
	struct ps_weather w;
	struct ps_patches P;
	struct ps_err e;
	struct ps_mtx_header h;
	int mf = 1, header = 1, average = 0, sun_hours = 0, verbose = 0, format = PS_MTX_ASCII;
	unsigned flags = 0;
	int i, ncols = 0, nsteps = 0, dbl;
	size_t cmdlen = 0;
	char *cmd;
	double *vec;
	void *mtx;
	ps_sky_opt_default(&o);
	for (i = 1; i < argc && argv[i][0] == '-' && argv[i][1]; i++) {
		const char *a = argv[i];
		if (strcmp(a, "--help") == 0 || (strcmp(a, "-h") == 0 && argc == 2)) {
			usage(stdout);
			return 0;
		}
		if (strcmp(a, "--version") == 0 || strcmp(a, "-V") == 0)
			return ps_cli_version("pssky");
		switch (a[1]) {
		case 'g':
			if (a[2])
				goto bad;
			triple(argc, argv, &i, "-g", o.ground);
			break;
		case 'c':
			if (a[2])
				goto bad;
			triple(argc, argv, &i, "-c", o.sky_color);
			break;
		case 'm': {
			double m;
			if (a[2])
				goto bad;
			m = number(argc, argv, &i, "-m");
			if (m != floor(m) || m < 1 || m > PS_PATCHES_MF_MAX) {
				fprintf(stderr, "pssky: -m: %g is not a whole number from 1 to %d\n", m,
				        PS_PATCHES_MF_MAX);
				return 2;
			}
			mf = (int)m;
			break;
		}
		case 'r':
			if (a[2] && strcmp(a + 2, "z") != 0)
				goto bad;
			o.rotation = number(argc, argv, &i, a);
			break;
		case 'd':   /* the sun alone: no sky, no ground */
			if (a[2])
				goto bad;
			o.sky_color[0] = o.sky_color[1] = o.sky_color[2] = 0.0;
			o.ground[0] = o.ground[1] = o.ground[2] = 0.0;
			break;
		case 's':   /* no sun */
			if (a[2])
				goto bad;
			o.sun_color[0] = o.sun_color[1] = o.sun_color[2] = 0.0;
			break;
		case 'u':
			if (a[2])
				goto bad;
			sun_hours = 1;
			break;
		case '5':
			if (a[2])
				goto bad;
			o.sun_disc = number(argc, argv, &i, "-5");
			if (!(o.sun_disc > 0 && o.sun_disc < 180)) {
				fprintf(stderr, "pssky: -5: the sun's size %g must be above 0 and below 180 "
				                "degrees\n", o.sun_disc);
				return 2;
			}
			break;
		case 'o':
			if (!a[2] || a[3] || !strchr("afd", a[2]))
				goto bad;
			format = a[2];
			break;
		case 'O':
			if (!a[2] || a[3] || (a[2] != '0' && a[2] != '1'))
				goto bad;
			o.output = a[2] == '1' ? PS_SKY_SOLAR : PS_SKY_VISIBLE;
			break;
		case 'h':   /* gendaymtx's no-header: -H from this release */
			if (a[2])
				goto bad;
			ps_cli_deprecated("pssky", "-h as gendaymtx's no-header", "-H (-h alone is the help)");
			header = 0;
			break;
		case 'H':
			if (a[2])
				goto bad;
			header = 0;
			break;
		case 'A':
			if (a[2])
				goto bad;
			average = 1;
			break;
		case 'E':
			if (a[2])
				goto bad;
			flags |= PS_WX_EPW_ILLUM;
			break;
		case 'e':   /* normalise with the exact sine, not gendaymtx's table */
			if (a[2])
				goto bad;
			o.exact_sine = 1;
			break;
		case 'v':
			if (a[2])
				goto bad;
			verbose = 1;
			break;
		default:
			goto bad;
		}
	}
	if (i < argc - 1) {
		usage(stderr);
		return 2;
	}
	if (i == argc - 1 && strcmp(argv[i], "-") != 0) {
		if (ps_weather_read(&w, argv[i], flags, &e) != 0) {
			fprintf(stderr, "pssky: %s\n", e.msg);
			return 1;
		}
	} else {
		uint8_t *data = NULL;
		size_t len = 0;
		int rc;
		if (read_stdin(&data, &len, &e) != 0) {
			fprintf(stderr, "pssky: %s\n", e.msg);
			return 1;
		}
		rc = ps_weather_parse(&w, (const char *)data, len, "(stdin)", flags, &e);
		free(data);
		if (rc != 0) {
			fprintf(stderr, "pssky: %s\n", e.msg);
			return 1;
		}
	}
	if (ps_patches_init(&P, mf, &e) != 0) {
		fprintf(stderr, "pssky: %s\n", e.msg);
		return 1;
	}
	/* which steps make columns */
	for (size_t k = 0; k < w.n; k++)
		if (!sun_hours || w.step[k].sun.alt > -0.533 / 2 * DEG)
			nsteps++;
	if (nsteps == 0) {
		fprintf(stderr, "pssky: %s: no time steps%s\n", w.name,
		        sun_hours ? " with the sun above the horizon (-u)" : "");
		return 1;
	}
	ncols = average ? 1 : nsteps;
	dbl = format == PS_MTX_DOUBLE;
	if ((size_t)ncols * (size_t)P.n * 3 > (SIZE_MAX / 8) ||
	    !(mtx = calloc((size_t)ncols * (size_t)P.n * 3, dbl ? sizeof(double) : sizeof(float))) ||
	    !(vec = malloc((size_t)P.n * 3 * sizeof *vec))) {
		fprintf(stderr, "pssky: out of memory for %d x %d patches\n", ncols, P.n);
		return 1;
	}
	{
		double *sum = NULL;
		int col = 0;
		if (average && !(sum = calloc((size_t)P.n * 3, sizeof *sum))) {
			fprintf(stderr, "pssky: out of memory\n");
			return 1;
		}
		for (size_t k = 0; k < w.n; k++) {
			const struct ps_wx_step *st = &w.step[k];
			struct ps_sky s;
			if (sun_hours && !(st->sun.alt > -0.533 / 2 * DEG))
				continue;
			ps_sky_step(&s, &w, k, &o, &e);
			if (s.bright_night)
				fprintf(stderr, "pssky: warning: %s:%d: unusually bright at %.1f on %d-%d (the "
				                "sun is below the horizon)\n",
				        w.name, st->line, st->hour, st->month, st->day);
			ps_sky_vector(&s, &P, PS_SKY_ALL, vec);
			for (int q = 0; q < 3 * P.n; q++)
				if (!isfinite(vec[q]) || (!dbl && !(fabs(vec[q]) <= FLT_MAX))) {
					/* a sky that is not finite is an error, never output */
					fprintf(stderr, "pssky: %s:%d: the sky of %d-%d %.2f h is not finite (direct "
					        "%g, diffuse %g): values out of range\n", w.name, st->line,
					        st->month, st->day, st->hour, st->dir, st->dif);
					return 1;
				}
			for (int q = 0; q < 3 * P.n; q++) {
				if (average)
					sum[q] += vec[q];
				else if (dbl)
					((double *)mtx)[(size_t)col * 3 * (size_t)P.n + (size_t)q] = vec[q];
				else
					((float *)mtx)[(size_t)col * 3 * (size_t)P.n + (size_t)q] = (float)vec[q];
			}
			col++;
		}
		if (average) {
			for (int q = 0; q < 3 * P.n; q++) {
				if (dbl)
					((double *)mtx)[q] = sum[q] / nsteps;
				else
					((float *)mtx)[q] = (float)(sum[q] / nsteps);
			}
			free(sum);
		}
	}
	/* the command line for the header */
	for (int k = 0; k < argc; k++)
		cmdlen += strlen(argv[k]) + 1;
	cmd = malloc(cmdlen + 1);
	if (!cmd) {
		fprintf(stderr, "pssky: out of memory\n");
		return 1;
	}
	cmd[0] = '\0';
	for (int k = 0; k < argc; k++) {
		if (k)
			strcat(cmd, " ");
		strcat(cmd, k ? argv[k] : "pssky");
	}
	memset(&h, 0, sizeof h);
	h.command = cmd;
	h.has_latlong = 1;
	h.lat = w.site.lat;
	h.lon = w.site.lon;
	h.nrows = P.n;
	h.ncols = ncols;
	h.naveraged = average ? nsteps : 0;
	h.format = format;
	if (verbose)
		fprintf(stderr, "pssky: %s: %s, %.2f N %.2f E, time zone %+g h; %zu steps, %d in the "
		                "matrix; %d patches (MF %d)\n",
		        w.name, w.site.name, w.site.lat, w.site.lon, w.site.tz, w.n, nsteps, P.n, mf);
	if (ps_mtx_write(stdout, "(stdout)", &h, header, mtx, dbl, &e) != 0) {
		fprintf(stderr, "pssky: %s\n", e.msg);
		return 1;
	}
	free(cmd);
	free(mtx);
	free(vec);
	ps_patches_free(&P);
	ps_weather_free(&w);
	return 0;
bad:
	fprintf(stderr, "pssky: unknown option '%s'\n", argv[i]);
	usage(stderr);
	return 2;
}
