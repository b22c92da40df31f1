/* SPDX-License-Identifier: ISC */
/* The sky of one time step as Radiance's gendaymtx makes it (the Perez
 * all-weather model of perez.h, its sun spread over the nearest patches,
 * the ground), as a vector of patch radiances for any subdivision, and as a
 * continuous sky for checks against the patches.
 *
 * Radiances are W/sr/m2 in Radiance's sense: luminance / 179 (the white
 * efficacy) for visible output, or solar radiance with PS_SKY_SOLAR.
 *
 * The patch vector (ps_sky_vector), step by step as gendaymtx:
 *   ground (patch 0): (Ed + Eb sin(alt)) / (pi 179) x ground reflectance,
 *     Ed the diffuse horizontal and Eb the direct normal illuminance
 *     (Eb counted only with the sun above the horizon);
 *   sky: each patch the model's relative luminance at its centre, scaled
 *     so that the patches' sum of radiance x sin(altitude) x solid angle
 *     is Ed / 179, times the sky colour (a sky whose sum is 0 is uniform).
 *     gendaymtx takes that sine from Radiance's table (tcos.c: the nearest
 *     of 1024 values a quadrant), which puts the sum up to 0.1 % off Ed;
 *     so does this unless exact_sine is set (ps_sky_table_sin);
 *   sun: Eb / 179 shared among the nsun patches (4) whose centres are
 *     nearest the sun, each by 1 / (1.002 - cos(angle to the sun)), divided
 *     by each patch's solid angle (or, with sun_disc > 0, put whole in the
 *     nearest patch over the disc's solid angle: the 5-phase method), times
 *     the sun colour.  The sun is added whatever its altitude, as gendaymtx.
 * A step with direct + diffuse <= 1e-4 is dark: every patch 0.
 *
 * The continuous sky (ps_sky_radiance) is the same relative luminance in
 * every direction, normalised by its own integral (adaptive quadrature,
 * ps_sky_normalise) so that its radiance x cos(zenith) over the upper
 * hemisphere is exactly Ed / 179; below the horizon it is the ground.  The
 * sun is a point (ps_sky_sun).  The patch vector converges to it as MF
 * grows (test_sky, bench_sky). */
#ifndef PS_SKY_H
#define PS_SKY_H

#include <stddef.h>

#include "err.h"
#include "patches.h"
#include "perez.h"
#include "quad.h"
#include "weather.h"

#define PS_WHITE_EFFICACY 179.0   /* lm/W: Radiance's luminous efficacy of white light */

enum ps_sky_part { PS_SKY_GROUND = 1, PS_SKY_DIFFUSE = 2, PS_SKY_SUN = 4, PS_SKY_ALL = 7 };
enum ps_sky_output { PS_SKY_VISIBLE = 0, PS_SKY_SOLAR = 1 };

struct ps_sky_opt {
	double rotation;     /* degrees the sky turns counter-clockwise seen from above (west of north) */
	double ground[3];    /* ground reflectance (0.2 0.2 0.2) */
	double sky_color[3]; /* (0.960 1.004 1.118), gendaymtx's default */
	double sun_color[3]; /* (1 1 1) */
	int output;          /* enum ps_sky_output */
	int nsun;            /* patches the sun is shared among, 1 to 4 (4) */
	double sun_disc;     /* > 0: 5-phase, the sun in one patch as a disc this wide (degrees) */
	int exact_sine;      /* 1: normalise the patches with the exact sine, not gendaymtx's table (0) */
};

/* One step's inputs (ps_sky_step fills them from a weather series). */
struct ps_sky_in {
	double dir, dif;     /* in units */
	int units;           /* enum ps_wx_units */
	double dew;          /* C */
	int doy;
	double sun_alt;      /* true altitude, radians */
	double sun_azi;      /* azimuth from north towards east, radians, before rotation */
};

struct ps_sky {
	int dark;            /* direct + diffuse <= 1e-4: everything 0 */
	int bright_night;    /* direct light with the sun below the horizon (gendaymtx warns) */
	struct ps_perez model;
	double sun_alt;      /* true altitude, radians */
	double sun_azi;      /* azimuth after the rotation */
	double sun_dir[3];   /* the true sun, after the rotation */
	double model_sun[3]; /* the sun the distribution centres on (zenith held to 3..90 deg) */
	double dif_lum;      /* diffuse horizontal illuminance, lux (x 179 W/m2 with PS_SKY_SOLAR) */
	double dir_lum;      /* direct normal illuminance, likewise */
	double ground_rad[3];/* ground radiance, reflectance included */
	struct ps_sky_opt opt;
	double norm;         /* integral of the relative luminance x cos over the upper
	                        hemisphere; 0 until ps_sky_normalise */
	double norm_err;     /* its estimated error */
};

void ps_sky_opt_default(struct ps_sky_opt *o);
/* Radiance's table sine (tsin in rtmath.h without fast math): what
 * gendaymtx weights the patches' illuminance with. */
double ps_sky_table_sin(double x);
/* Radiance's brightness of an RGB triple (its luminance weights). */
double ps_sky_bright(const double rgb[3]);

/* The sky of one step from its inputs. */
void ps_sky_init(struct ps_sky *s, const struct ps_sky_in *in, const struct ps_sky_opt *o);
/* The sky of step i of a weather series. */
int ps_sky_step(struct ps_sky *s, const struct ps_weather *w, size_t i, const struct ps_sky_opt *o,
                struct ps_err *e);

/* The patch radiances (3 per patch, P->n patches) of the parts asked for. */
void ps_sky_vector(const struct ps_sky *s, const struct ps_patches *P, unsigned parts, double *rgb);

/* The sun's patches as ps_sky_vector puts it: the nearest centres first
 * (as many as the options share it among), their radiance per unit of sun
 * colour in v, and in v1 the radiance of the nearest one if it held the
 * sun alone.  Returns how many (0: no sun). */
int ps_sky_sun_patches(const struct ps_sky *s, const struct ps_patches *P, int idx[4], double v[4],
                       double *v1);

/* Normalise the continuous sky (reltol: the quadrature's relative tolerance,
 * e.g. 1e-10).  Returns -1 if the quadrature did not converge. */
int ps_sky_normalise(struct ps_sky *s, double reltol, struct ps_err *e);
/* Radiance of the continuous sky in direction d (unit; X east, Y north,
 * Z up): the diffuse sky above the horizon, the ground below, as parts asks
 * (PS_SKY_SUN is ignored: see ps_sky_sun).  Needs ps_sky_normalise. */
void ps_sky_radiance(const struct ps_sky *s, const double d[3], unsigned parts, double rgb[3]);
/* The sun as a point: its direction and its normal irradiance in radiance
 * units (direct / 179 x sun colour; 0 when dark or without a sun). */
void ps_sky_sun(const struct ps_sky *s, double dir[3], double rgb[3]);

/* Integral over the upper hemisphere of weight(d) x (coef . L(d)) d omega,
 * L the continuous sky's diffuse part, by adaptive quadrature in zenith
 * angle and azimuth (breaks at the sun, the horizon cap and the extra
 * zenith angles zb[] and azimuths ab[] the weight needs, radians).  The
 * error is the quadrature's estimate. */
typedef double (*ps_sky_weight_fn)(const double d[3], void *ctx);
int ps_sky_integrate(const struct ps_sky *s, const double coef[3], ps_sky_weight_fn weight,
                     void *ctx, const double *zb, int nzb, const double *ab, int nab,
                     double reltol, struct ps_quad *r, struct ps_err *e);

#endif
