/* SPDX-License-Identifier: ISC */
#include "skyclass.h"

#include <math.h>

#include "year.h"

double ps_skyclass_erbs_diffuse_fraction(double kt)
{
	if (kt <= 0.22)
		return 1.0 - 0.09 * (kt > 0 ? kt : 0.0);
	if (kt <= 0.80)
		return 0.9511 + kt * (-0.1604 + kt * (4.388 + kt * (-16.638 + kt * 12.336)));
	return 0.165;
}

double ps_skyclass_clearness_from_fraction(double fd, double g, double zenith)
{
	double dh = fd * g, in, z3 = 1.041 * zenith * zenith * zenith;
	if (!(dh > 0))
		return 1.0;
	in = (g - dh) / cos(zenith);
	return ((dh + in) / dh + z3) / (1.0 + z3);
}

int ps_skyclass_from_global(const struct ps_site *site, int doy, double std_hour, double glob_lux,
                            double *kt, double *eps)
{
	struct ps_sunpos p;
	double e0, k, e;
	if (!isfinite(glob_lux) || glob_lux < 0 || doy < 1 || doy > 366)
		return -1;
	ps_sun_position(site, doy, std_hour, &p);
	if (p.alt < PS_SKYCLASS_MIN_ALT_DEG * M_PI / 180.0)
		return -1;
	e0 = PS_LUMINOUS_SOLAR_CONSTANT * (1.0 + 0.033 * cos(2.0 * M_PI * doy / 365.0));
	k = glob_lux / (e0 * sin(p.alt));
	e = ps_skyclass_clearness_from_fraction(ps_skyclass_erbs_diffuse_fraction(k), glob_lux, M_PI / 2 - p.alt);
	if (kt)
		*kt = k;
	if (eps)
		*eps = e;
	return ps_year_class(e);
}
