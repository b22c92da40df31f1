/* SPDX-License-Identifier: ISC */
#include "mtx.h"

#include <stdint.h>

/* "ascii", "float", "double". */
static const char *ps_mtx_format_name(int format)
{
	switch (format) {
	case PS_MTX_ASCII: return "ascii";
	case PS_MTX_FLOAT: return "float";
	case PS_MTX_DOUBLE: return "double";
	}
	return "unknown";
}

static int little_endian(void)
{
	const uint16_t one = 1;
	return *(const uint8_t *)&one == 1;
}

int ps_mtx_write(FILE *fp, const char *path, const struct ps_mtx_header *h, int header,
                 const void *data, int data_double, struct ps_err *e)
{
	const float *df = data;
	const double *dd = data;
	if (header) {
		fputs("#?RADIANCE\n", fp);
		if (h->command)
			fprintf(fp, "%s\n", h->command);
		if (h->has_latlong)
			fprintf(fp, "LATLONG= %.8f %.8f\n", h->lat, h->lon);
		fprintf(fp, "NROWS=%d\nNCOLS=%d\n", h->nrows, h->ncols);
		if (h->naveraged > 0)
			fprintf(fp, "NAVERAGED=%d\n", h->naveraged);
		fputs("NCOMP=3\n", fp);
		if (h->format != PS_MTX_ASCII)
			fprintf(fp, "BYTEORDER=%s\n", little_endian() ? "LittleEndian" : "BigEndian");
		fprintf(fp, "FORMAT=%s\n\n", ps_mtx_format_name(h->format));
	}
	for (int r = 0; r < h->nrows; r++) {
		for (int c = 0; c < h->ncols; c++) {
			size_t at = 3 * ((size_t)c * (size_t)h->nrows + (size_t)r);
			double v[3];
			for (int k = 0; k < 3; k++)
				v[k] = data_double ? dd[at + k] : (double)df[at + k];
			if (h->format == PS_MTX_ASCII) {
				int d = h->digits > 0 ? h->digits : 3;
				fprintf(fp, "%.*g %.*g %.*g\n", d, v[0], d, v[1], d, v[2]);
			} else if (h->format == PS_MTX_FLOAT) {
				float f[3] = { (float)v[0], (float)v[1], (float)v[2] };
				fwrite(f, sizeof f[0], 3, fp);
			} else {
				fwrite(v, sizeof v[0], 3, fp);
			}
		}
		if (h->format == PS_MTX_ASCII && h->ncols > 1)
			fputc('\n', fp);
		if (ferror(fp))
			return ps_err_sys(e, "%s: write error", path);
	}
	if (fflush(fp) != 0 || ferror(fp))
		return ps_err_sys(e, "%s: write error", path);
	return 0;
}
