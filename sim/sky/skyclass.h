/* SPDX-License-Identifier: ISC */
/* The sky class of an hour from one measured number: the global horizontal
 * illuminance a rooftop sensor reads, at a site, date and standard time.
 *
 * The reading is set against the extraterrestrial horizontal illuminance of
 * the sun at that moment (the luminous solar constant 133.8 klx, Darula,
 * Kittler & Gueymard 2005, Solar Energy 79(5) 559-565; the orbit's
 * eccentricity 1 + 0.033 cos(2 pi doy / 365), Duffie & Beckman), giving the
 * clearness index kt.  The diffuse fraction follows from kt by the Erbs,
 * Klein & Duffie (1982, Solar Energy 28(4) 293-302) correlation, and with the
 * diffuse and direct parts Perez's clearness epsilon
 * ((Dh + In) / Dh + 1.041 Z^3) / (1 + 1.041 Z^3) (Perez et al. 1990), which
 * ps_year_class() bins like the year's own hours (overcast below 1.23,
 * clear from 4.5).  The luminous kt stands in for the radiant one Erbs fitted
 * (the efficacies of sunlight outside and under the sky differ by some per
 * cent).  Against the class from a weather file's own direct and diffuse
 * (test_skyclass): 96.0 % of a synthetic year's hours agree, 70.8 % of San
 * Francisco's measured TMY3 year's (one hour of 4021 judged clear for
 * overcast or back), and 51.1 % of Radiance's 45 gendaymtx test hours
 * (Mountain View, hazy mornings whose diffuse share is above Erbs's fit;
 * none clear for overcast or back).
 *
 * Below 5 degrees of sun altitude the reading cannot be judged (a sensor's
 * cosine error and the horizon dominate): -1. */
#ifndef PS_SKYCLASS_H
#define PS_SKYCLASS_H

#include "sun.h"

#define PS_LUMINOUS_SOLAR_CONSTANT 133800.0   /* lux */
#define PS_SKYCLASS_MIN_ALT_DEG 5.0

/* Erbs diffuse fraction of a clearness index. */
double ps_skyclass_erbs_diffuse_fraction(double kt);
/* Perez clearness from the diffuse fraction, the clearness index's global
 * reading g (any unit) and the sun's zenith (radians). */
double ps_skyclass_clearness_from_fraction(double fd, double g, double zenith);
/* The class (enum ps_skyclass) of a global horizontal reading glob_lux on
 * day of year doy at standard time std_hour; *kt and *eps (either may be
 * NULL) get the clearness index and Perez clearness.  -1 when the sun is
 * too low or the reading not finite. */
int ps_skyclass_from_global(const struct ps_site *site, int doy, double std_hour, double glob_lux,
                            double *kt, double *eps);

#endif
