/* SPDX-License-Identifier: ISC */
/* Colour-correction filters: from a filter's spectral response to the R, G, B
 * coefficients psens takes, and how far the sensor strays from true
 * illuminance under each CIE illuminant.
 *
 * Filter file: "wavelength_nm value" a line, '#' comments, blank lines; the
 * value is the sensor's relative spectral response (detector x filter), as a
 * fraction or in percent (a file whose largest value exceeds 2 is read as
 * percent, or force it).  Between points it is linear; outside its range 0.
 *
 * Coefficients: least squares of the response s on span{x-bar, y-bar, z-bar}
 * on the CMF table's 1-nm grid (360-830 nm) gives c_xyz; the RGB coefficients
 * are M^T c_xyz with M Radiance's RGB-to-XYZ matrix (standard primaries, white
 * 0.3333 0.3333), so that s = V(lambda) gives 0.265074 0.670115 0.064811. */
#ifndef PS_FILTER_H
#define PS_FILTER_H

#include <stddef.h>

#include "err.h"

struct ps_filter {
	char *path;
	int n;
	double *nm, *value;    /* as read; value scaled to a fraction */
	int percent;           /* 1 when the file was read as percent */
};

enum { PS_FILTER_PERCENT_AUTO = -1, PS_FILTER_FRACTION = 0, PS_FILTER_PERCENT = 1 };

int ps_filter_parse(struct ps_filter *f, const char *text, size_t len, const char *name,
                    int percent, struct ps_err *e);
int ps_filter_read(struct ps_filter *f, const char *path, int percent, struct ps_err *e);
void ps_filter_free(struct ps_filter *f);
/* Response at a wavelength: linear, 0 outside the file's range. */
double ps_filter_at(const struct ps_filter *f, double nm);

struct ps_illum_error {
	const char *name;
	double spectral;       /* relative reading error of the real response */
	double rgb;            /* the same for the R,G,B representation psens uses */
};

struct ps_filter_report {
	double xyz[3];         /* c_xyz */
	double rgb[3];         /* the coefficients for psens -R -G -B */
	double residual;       /* ||s - projection|| / ||s|| on the grid */
	double condition;      /* condition number of the normal equations */
	double f1p;            /* CIE f1' (normalised under illuminant A), 380-780 nm */
	double lo, hi;         /* the filter's wavelength range */
	int outside;           /* 1 when the range does not cover 380-780 nm */
	const char *calibration;
	struct ps_illum_error illum[16];
	int nillum;
};

/* calibration: the illuminant the sensor is calibrated under ("A"). */
int ps_filter_analyse(const struct ps_filter *f, const char *calibration,
                      struct ps_filter_report *r, struct ps_err *e);
/* Read a filter file and give its R,G,B coefficients (psens -f). */
int ps_filter_rgb(const char *path, double rgb[3], struct ps_err *e);

#endif
