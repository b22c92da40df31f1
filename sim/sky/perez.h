/* SPDX-License-Identifier: ISC */
/* The Perez all-weather sky for one time step:
 *   Perez, Seals, Michalsky 1993, "All-weather model for sky luminance
 *   distribution - preliminary configuration and validation", Solar Energy
 *   50(3) 235-245, with its erratum (Solar Energy 51(5) 423): the relative
 *   luminance  l = (1 + a exp(b / cos zeta)) (1 + c exp(d gamma) + e cos^2 gamma)
 *   (zeta the zenith angle of the sky point, gamma its angle from the sun),
 *   a..e from the clearness bin's coefficients (Table 1; the erratum's c and
 *   d formulas in the first bin);
 *   Perez, Ineichen, Seals, Michalsky, Stewart 1990, "Modeling daylight
 *   availability and irradiance components from direct and global
 *   irradiance", Solar Energy 44(5) 271-289: clearness epsilon (eq. 1),
 *   brightness delta (eq. 2), precipitable water from the dew point (eq. 3),
 *   luminous efficacy of the diffuse and the direct light (eqs. 7, 8,
 *   Table 4).
 *
 * With the choices Radiance's gendaymtx makes, so that a sky agrees with it:
 * the solar constant 1367 W/m2 (127.5 klx for illuminance input), Kasten's
 * air mass, Spencer's eccentricity; the sun's zenith angle held to 3..90
 * degrees in the model (the sky distribution and the efficacies; a sun below
 * the horizon counts as on it); epsilon held to 1..11.9 and delta to
 * 0.01..0.6 (illuminance input: epsilon to 12, converted to irradiance
 * by up to five fixed-point steps); delta at least 0.2 in the distribution
 * when 1.065 < epsilon < 2.8; negative luminance read as 0.
 *
 * Clearness bins: [1, 1.065), [1.065, 1.23), [1.23, 1.5), [1.5, 1.95),
 * [1.95, 2.8), [2.8, 4.5), [4.5, 6.2), [6.2, 12.01): a value on an edge
 * belongs to the bin above it.  The model is not continuous across an edge:
 * the coefficients (and so the distribution and both efficacies) jump; every
 * value stays finite.
 *
 * Stiff corner: in bin 5 (2.8 <= epsilon < 4.5) with the sun within 12
 * degrees of the horizon and a brightness above about 0.5, both a and b are
 * positive, so the gradation a exp(b / cos zeta) grows without bound towards
 * the horizon (b up to 0.32: e^32 at cos zeta = 0.01).  Everywhere else
 * with b > 0, a is negative and the luminance there is read as 0 (a black
 * band above the horizon).  The continuous sky (ps_perez_rel) holds cos zeta
 * at 0.01 or more in the gradation term, as Radiance's perezlum.cal does, so
 * it stays bounded and integrable; the patches sample their centres as
 * gendaymtx does (cos zeta 0.105 for the horizon row at MF 1, 0.018 at MF 6:
 * such an hour's horizon row grows with MF; test_sky prints how much). */
#ifndef PS_PEREZ_H
#define PS_PEREZ_H

#define PS_PEREZ_NBINS 8
#define PS_SOLAR_CONSTANT 1367.0         /* W/m2 */
#define PS_SOLAR_CONSTANT_LUX 127500.0   /* lux */
#define PS_PEREZ_MIN_ZENITH_DEG 3.0
#define PS_PEREZ_COS_ZETA_MIN 0.01

struct ps_perez_in {
	double dir, dif;     /* direct normal, diffuse horizontal (W/m2, or lux if photometric) */
	int photometric;     /* 1: the values are illuminances */
	double dew;          /* surface dew point, C */
	int doy;             /* day of the year */
	double sun_alt;      /* true solar altitude, radians */
};

struct ps_perez {
	double zenith;       /* the model's sun zenith angle, radians (3 to 90 degrees) */
	double epsilon;      /* clearness (held) */
	double delta;        /* brightness (held) */
	int bin;             /* clearness bin 0..7 */
	double water;        /* precipitable water, cm */
	double air_mass;
	double eccentricity;
	double dir_irr, dif_irr;  /* W/m2 (from illuminance input: the converted values) */
	double dir_lux, dif_lux;  /* lux (direct normal, diffuse horizontal) */
	double coef[5];      /* a, b, c, d, e of the distribution */
};

/* Lower edge of clearness bin k (k = 0..8; edge 8 is the top, 12.01). */
double ps_perez_bin_edge(int k);
/* The bin of a clearness (edges belong to the bin above). */
int ps_perez_bin(double epsilon);
/* Everything for one step. */
void ps_perez_init(struct ps_perez *p, const struct ps_perez_in *in);
/* Relative luminance (never negative) at a unit vector d of the sky, with
 * the model's sun at sun (the vector of altitude 90 degrees minus
 * p->zenith). */
double ps_perez_rel_dir(const struct ps_perez *p, const double d[3], const double sun[3]);

#endif
