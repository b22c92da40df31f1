/* SPDX-License-Identifier: ISC */
/* Photosensor angular sensitivity: the rsensor / SPOT table layout, its two
 * readings, and the built-in ideal sensors.
 *
 * File layout: an optional line starting with "Elevation", then a line
 * "degrees phi0 phi1 ..." (azimuths from 0, increasing, reaching at least 270,
 * below 360), then rows "theta s0 s1 ..." (polar angles from 0, increasing,
 * at most 180).  Tabs or spaces.  Azimuth 0 is the view's up vector and
 * azimuth grows towards the picture's left.
 *
 * The "Elevation" line may state the field, "Elevation field 90": the last
 * row must then be at that polar angle.  Without it a table is taken only
 * when it reaches 90 degrees or ends with a zero row, so that a cut copy
 * is never read as a narrow sensor (psens(1), "Sensitivity files").
 *
 * Readings:
 *   linear (the default): bilinear in theta and phi between the table's
 *     points, periodic in phi, zero beyond the last theta.  Continuous, so a
 *     result never depends on where a cell edge happens to fall in the room,
 *     and its error on smooth sensitivities is two thirds of cell's (cosine
 *     table at 2 degrees: -1.0e-4 against -1.5e-4).
 *   cell: rsensor's: each value holds between the midpoints to its
 *     neighbours; the last row's cell ends at 1.5 last - 0.5 previous.  Use it
 *     to agree with rsensor.
 *
 * Internally both are the same thing: a grid of patches in (theta, phi), each
 * bilinear, with running integrals so that
 *   M(theta, phi) = integral_0^theta S(t, phi) sin t dt
 * has a closed form: the exact pixel weights are line integrals of M. */
#ifndef PS_SENSOR_H
#define PS_SENSOR_H

#include <math.h>
#include <stddef.h>

#include "err.h"

enum ps_reading { PS_READ_LINEAR = 0, PS_READ_CELL = 1 };
enum ps_sensor_kind { PS_SENS_TABLE = 0, PS_SENS_COSINE, PS_SENS_UNIFORM };

struct ps_sensor {
	int kind;               /* enum ps_sensor_kind */
	char *path;             /* file name, or "builtin:cosine" */
	/* the table as read (degrees) */
	int ntheta, nphi;
	double *theta, *phi;    /* ntheta, nphi */
	double *val;            /* ntheta * nphi, row-major by theta */
	double total;           /* sum of all table values (the paper's "total sensitivity") */
	double max_value;
	/* the reading in use (ps_sensor_set_reading) */
	int reading;
	int nt, np;             /* patches: nt in theta, np in phi */
	double *tb;             /* nt + 1 theta breakpoints, radians, tb[0] = 0 */
	double *pb;             /* np + 1 phi breakpoints, radians, pb[np] = pb[0] + 2 pi */
	double *corner;         /* (nt) x (np + 1) x 2: S at (tb[i], pb[j]) and (tb[i+1], pb[j]) */
	double *cum;            /* (nt + 1) x np x 2: integral_0^tb[i] S(t, phi) sin t dt along
	                           each patch's left and right edge */
	double *mcoef;          /* nt x np x 6: per patch edge (K, a, b) with
	                           M(theta) = K + a (1 - cos theta) + b (sin theta - theta cos theta)
	                           (ps_sensor_m_patch) */
	double theta_end;       /* radians: S = 0 beyond */
};

/* Read a sensitivity file; errors name file:line. */
int ps_sensor_read(struct ps_sensor *s, const char *path, struct ps_err *e);
/* Parse from memory (name for messages). */
int ps_sensor_parse(struct ps_sensor *s, const char *text, size_t len, const char *name,
                    struct ps_err *e);
/* The ideal cosine sensor (S = cos theta up to 90 degrees: irradiance) or
 * the uniform one (S = 1 everywhere: solid angle). */
int ps_sensor_builtin(struct ps_sensor *s, int kind, struct ps_err *e);
/* Open "builtin:cosine", "builtin:uniform" or a file. */
int ps_sensor_open(struct ps_sensor *s, const char *name, struct ps_err *e);
/* Choose the reading (builds the patch grid); tables start as linear. */
int ps_sensor_set_reading(struct ps_sensor *s, int reading, struct ps_err *e);
void ps_sensor_free(struct ps_sensor *s);

/* Parse "linear" or "cell"; -1 if neither. */
int ps_sensor_reading_parse(const char *name);
const char *ps_sensor_reading_name(int reading);

/* Sensitivity at (theta, phi), radians, under the current reading. */
double ps_sensor_value(const struct ps_sensor *s, double theta, double phi);
/* M(theta, phi) = integral_0^theta S(t, phi) sin t dt. */
double ps_sensor_m(const struct ps_sensor *s, double theta, double phi);
/* Same with the patch indices already known (theta within patch i, phi
 * within patch j, phi in [pb[0], pb[0] + 2 pi)); i == nt means beyond the end. */
double ps_sensor_m_in(const struct ps_sensor *s, int i, int j, double theta, double phi);
/* Below this polar angle (radians) M is summed from 1 - cos t = 2 sin^2(t/2)
 * and the series of sin t - t cos t, which keep their relative precision
 * however small t is; above it the closed form's cancellation costs at most
 * 2e-14 relative. */
#define PS_SENSOR_SMALL_THETA 0.1

/* sin t - t cos t for 0 <= t < PS_SENSOR_SMALL_THETA: its series
 * sum (-1)^(n+1) 2n t^(2n+1) / (2n+1)!, to n = 5 (the next term is below
 * 1e-18 of the sum). */
static inline double ps_sensor_sin_t_cos_small(double t)
{
	double t2 = t * t;
	return t * t2 *
	       (1.0 / 3 - t2 * (1.0 / 30 - t2 * (1.0 / 840 - t2 * (1.0 / 45360 - t2 * (1.0 / 3991680)))));
}

/* M in one patch edge's piece, k = (K, a, b) of mcoef, st and ct the sine
 * and cosine of theta (used above PS_SENSOR_SMALL_THETA only). */
static inline double ps_sensor_m_patch(const double *k, double theta, double st, double ct)
{
	if (theta < PS_SENSOR_SMALL_THETA) {
		double sh = sin(0.5 * theta);
		return k[0] + k[1] * (2.0 * sh * sh) + k[2] * ps_sensor_sin_t_cos_small(theta);
	}
	return (k[0] + k[1]) + k[2] * st - (k[1] + k[2] * theta) * ct;
}

/* M of a builtin (kind PS_SENS_COSINE or PS_SENS_UNIFORM), which depends on
 * theta alone; inline: the exact weights take it at every node.  The
 * uniform sensor's 1 - cos theta is 2 sin^2(theta/2): exact to the last
 * digits for the smallest angles. */
static inline double ps_sensor_m_builtin(int kind, double theta)
{
	if (kind == PS_SENS_COSINE) {
		double st = theta >= M_PI / 2 ? 1.0 : sin(theta);
		return 0.5 * st * st;
	}
	if (theta >= M_PI)
		return 2.0;
	{
		double sh = sin(0.5 * theta);
		return 2.0 * sh * sh;
	}
}
/* Patch indices for a direction; phi is reduced into [pb[0], pb[0] + 2 pi). */
void ps_sensor_locate(const struct ps_sensor *s, double theta, double *phi, int *i, int *j);
/* Integral of S over the whole sphere (exact for the reading). */
double ps_sensor_integral(const struct ps_sensor *s);
/* Largest polar angle with non-zero sensitivity (radians). */
double ps_sensor_extent(const struct ps_sensor *s);

#endif
