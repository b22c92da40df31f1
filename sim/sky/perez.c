/* SPDX-License-Identifier: ISC */
#include "perez.h"

#include <math.h>

/* Perez, Seals, Michalsky 1993, Table 1 (with the erratum): for each
 * clearness bin, a1..a4, b1..b4, c1..c4, d1..d4, e1..e4. */
static const double sky_coef[PS_PEREZ_NBINS][5][4] = {
	{ { 1.3525, -0.2576, -0.2690, -1.4366 }, { -0.7670, 0.0007, 1.2734, -0.1233 },
	  { 2.8000, 0.6004, 1.2375, 1.0000 }, { 1.8734, 0.6297, 0.9738, 0.2809 },
	  { 0.0356, -0.1246, -0.5718, 0.9938 } },
	{ { -1.2219, -0.7730, 1.4148, 1.1016 }, { -0.2054, 0.0367, -3.9128, 0.9156 },
	  { 6.9750, 0.1774, 6.4477, -0.1239 }, { -1.5798, -0.5081, -1.7812, 0.1080 },
	  { 0.2624, 0.0672, -0.2190, -0.4285 } },
	{ { -1.1000, -0.2515, 0.8952, 0.0156 }, { 0.2782, -0.1812, -4.5000, 1.1766 },
	  { 24.7219, -13.0812, -37.7000, 34.8438 }, { -5.0000, 1.5218, 3.9229, -2.6204 },
	  { -0.0156, 0.1597, 0.4199, -0.5562 } },
	{ { -0.5484, -0.6654, -0.2672, 0.7117 }, { 0.7234, -0.6219, -5.6812, 2.6297 },
	  { 33.3389, -18.3000, -62.2500, 52.0781 }, { -3.5000, 0.0016, 1.1477, 0.1062 },
	  { 0.4659, -0.3296, -0.0876, -0.0329 } },
	{ { -0.6000, -0.3566, -2.5000, 2.3250 }, { 0.2937, 0.0496, -5.6812, 1.8415 },
	  { 21.0000, -4.7656, -21.5906, 7.2492 }, { -3.5000, -0.1554, 1.4062, 0.3988 },
	  { 0.0032, 0.0766, -0.0656, -0.1294 } },
	{ { -1.0156, -0.3670, 1.0078, 1.4051 }, { 0.2875, -0.5328, -3.8500, 3.3750 },
	  { 14.0000, -0.9999, -7.1406, 7.5469 }, { -3.4000, -0.1078, -1.0750, 1.5702 },
	  { -0.0672, 0.4016, 0.3017, -0.4844 } },
	{ { -1.0000, 0.0211, 0.5025, -0.5119 }, { -0.3000, 0.1922, 0.7023, -1.6317 },
	  { 19.0000, -5.0000, 1.2438, -1.9094 }, { -4.0000, 0.0250, 0.3844, 0.2656 },
	  { 1.0468, -0.3788, -2.4517, 1.4656 } },
	{ { -1.0500, 0.0289, 0.4260, 0.3590 }, { -0.3250, 0.1156, 0.7781, 0.0025 },
	  { 31.0625, -14.5000, -46.1148, 55.3750 }, { -7.2312, 0.4050, 13.3500, 0.6234 },
	  { 1.5000, -0.6426, 1.8564, 0.5636 } },
};

/* Perez et al. 1990, Table 4: a, b, c, d of the diffuse (eq. 7) and the
 * direct (eq. 8) luminous efficacy, lm/W. */
static const double eff_diffuse[PS_PEREZ_NBINS][4] = {
	{ 97.24, -0.46, 12.00, -8.91 },   { 107.22, 1.15, 0.59, -3.95 },
	{ 104.97, 2.96, -5.53, -8.77 },   { 102.39, 5.59, -13.95, -13.90 },
	{ 100.71, 5.94, -22.75, -23.74 }, { 106.42, 3.83, -36.15, -28.83 },
	{ 141.88, 1.90, -53.24, -14.03 }, { 152.23, 0.35, -45.27, -7.98 },
};
static const double eff_direct[PS_PEREZ_NBINS][4] = {
	{ 57.20, -4.55, -2.98, 117.12 }, { 98.99, -3.46, -1.21, 12.38 },
	{ 109.83, -4.90, -1.71, -8.81 }, { 110.34, -5.84, -1.99, -4.56 },
	{ 106.36, -3.97, -1.75, -6.16 }, { 107.19, -1.25, -1.51, -26.73 },
	{ 105.75, 0.77, -1.26, -34.44 }, { 101.18, 1.58, -1.10, -8.29 },
};

static const double bin_edge[PS_PEREZ_NBINS + 1] = { 1.000, 1.065, 1.230, 1.500, 1.950,
	                                              2.800, 4.500, 6.200, 12.01 };

double ps_perez_bin_edge(int k)
{
	return bin_edge[k < 0 ? 0 : k > PS_PEREZ_NBINS ? PS_PEREZ_NBINS : k];
}

int ps_perez_bin(double eps)
{
	for (int k = PS_PEREZ_NBINS - 1; k > 0; k--)
		if (eps >= bin_edge[k])
			return k;
	return 0;
}

/* Kasten 1966 relative optical air mass. */
static double air_mass(double z)
{
	return 1.0 / (cos(z) + 0.15 * pow(93.885 - z * (180.0 / M_PI), -1.253));
}

/* Spencer 1971 eccentricity correction. */
static double eccentricity(int doy)
{
	double g = 2.0 * M_PI * (doy - 1) / 365.0;
	return 1.00011 + 0.034221 * cos(g) + 0.00128 * sin(g) + 0.000719 * cos(2 * g) +
	       0.000077 * sin(2 * g);
}

static double brightness(const struct ps_perez *p, double dif_irr)
{
	return dif_irr * p->air_mass / (PS_SOLAR_CONSTANT * p->eccentricity);
}

static double clearness(const struct ps_perez *p, double dir_irr, double dif_irr, double top)
{
	double k = 1.041 * p->zenith * p->zenith * p->zenith;
	if (!(dif_irr > 0))
		return top;   /* no diffuse light: as clear as the model goes */
	return ((dif_irr + dir_irr) / dif_irr + k) / (1.0 + k);
}

static double hold(double x, double lo, double hi)
{
	return x < lo ? lo : x > hi ? hi : x;
}

static double diffuse_efficacy(const struct ps_perez *p)
{
	const double *k = eff_diffuse[p->bin];
	return k[0] + k[1] * p->water + k[2] * cos(p->zenith) + k[3] * log(p->delta);
}

static double direct_efficacy(const struct ps_perez *p)
{
	const double *k = eff_direct[p->bin];
	double v = k[0] + k[1] * p->water + k[2] * exp(5.73 * p->zenith - 5.0) + k[3] * p->delta;
	return v > 0 ? v : 0.0;
}

static void distribution(struct ps_perez *p)
{
	const double(*x)[4] = sky_coef[p->bin];
	double z = p->zenith, dl = p->delta;
	if (p->epsilon > 1.065 && p->epsilon < 2.8 && dl < 0.2)
		dl = 0.2;
	for (int i = 0; i < 5; i++)
		p->coef[i] = x[i][0] + x[i][1] * z + dl * (x[i][2] + x[i][3] * z);
	if (p->bin == 0) {   /* the erratum's c and d for overcast skies */
		p->coef[2] = exp(pow(dl * (x[2][0] + x[2][1] * z), x[2][2])) - x[2][3];
		p->coef[3] = -exp(dl * (x[3][0] + x[3][1] * z)) + x[3][2] + dl * x[3][3];
	}
}

void ps_perez_init(struct ps_perez *p, const struct ps_perez_in *in)
{
	double alt = in->sun_alt, z;
	const double zmin = PS_PEREZ_MIN_ZENITH_DEG * (M_PI / 180.0);
	if (alt <= 0.0)
		z = M_PI / 2;
	else if (alt >= M_PI / 2 - zmin)
		z = zmin;
	else
		z = M_PI / 2 - alt;
	p->zenith = z;
	p->water = exp(0.07 * in->dew - 0.075);
	p->air_mass = air_mass(z);
	p->eccentricity = eccentricity(in->doy);
	if (!in->photometric) {
		p->dir_irr = in->dir;
		p->dif_irr = in->dif;
		p->epsilon = hold(clearness(p, in->dir, in->dif, 11.9), 1.0, 11.9);
		p->delta = hold(brightness(p, in->dif), 0.01, 0.6);
		p->bin = ps_perez_bin(p->epsilon);
		p->dif_lux = in->dif * diffuse_efficacy(p);
		p->dir_lux = in->dir * direct_efficacy(p);
	} else {
		/* illuminance to irradiance: start from the solar constants' ratio,
		 * then divide by the bin's efficacies until both settle within
		 * 10 W/m2 (at most five steps), as gendaymtx does */
		double dif = in->dif * PS_SOLAR_CONSTANT / PS_SOLAR_CONSTANT_LUX;
		double dir = in->dir * PS_SOLAR_CONSTANT / PS_SOLAR_CONSTANT_LUX;
		double last_dif = 0.1, last_dir = 0.1;
		p->epsilon = hold(clearness(p, dir, dif, 12.0), 1.0, 12.0);
		p->delta = hold(brightness(p, dif), 0.01, 0.6);
		for (int step = 0; step < 5 && (fabs(dif - last_dif) > 10.0 || fabs(dir - last_dir) > 10.0);
		     step++) {
			double de;
			last_dif = dif;
			last_dir = dir;
			p->bin = ps_perez_bin(p->epsilon);
			dif = in->dif / diffuse_efficacy(p);
			de = direct_efficacy(p);
			if (de > 0.1)
				dir = in->dir / de;
			p->epsilon = hold(clearness(p, dir, dif, 12.0), 1.0, 12.0);
			p->delta = hold(brightness(p, dif), 0.01, 0.6);
		}
		p->bin = ps_perez_bin(p->epsilon);
		p->dir_irr = dir;
		p->dif_irr = dif;
		p->dir_lux = in->dir;
		p->dif_lux = in->dif;
	}
	distribution(p);
}

/* Relative luminance at cos zeta (of the sky point) and gamma (its angle
 * from the sun, radians); never negative. */
static double ps_perez_rel(const struct ps_perez *p, double cos_zeta, double gamma)
{
	double cz = cos_zeta < PS_PEREZ_COS_ZETA_MIN ? PS_PEREZ_COS_ZETA_MIN : cos_zeta;
	double cg = cos(gamma);
	double l = (1.0 + p->coef[0] * exp(p->coef[1] / cz)) *
	           (1.0 + p->coef[2] * exp(p->coef[3] * gamma) + p->coef[4] * cg * cg);
	return l > 0 ? l : 0.0;
}

double ps_perez_rel_dir(const struct ps_perez *p, const double d[3], const double sun[3])
{
	double c = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
	return ps_perez_rel(p, d[2], acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c));
}
