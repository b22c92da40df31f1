/* SPDX-License-Identifier: ISC */
#include "cie.h"

#include <stdio.h>
#include <string.h>

const char *const ps_cie_illuminant_names[] = { "A", "D65", "FL2", "FL7", "FL11", "FL12", "HP1",
                                                "HP2", "HP3", "HP4", "HP5", "LED-B3", "LED-B4",
                                                NULL };

static const struct ps_spectrum *find(const char *file, int column)
{
	for (const struct ps_spectrum *s = ps_cie_tables; s->file; s++)
		if (strcmp(s->file, file) == 0 && s->column == column)
			return s;
	return NULL;
}

const struct ps_spectrum *ps_cie_cmf(int k)
{
	return find("cie1931_2deg_cmf_1nm", k + 1);
}

const struct ps_spectrum *ps_cie_v(void)
{
	return find("cie_photopic_V_1nm", 1);
}

const struct ps_spectrum *ps_cie_illuminant(const char *name)
{
	char file[64];
	const struct ps_spectrum *s;
	snprintf(file, sizeof file, "cie_illum_%s_1nm", name);
	if ((s = find(file, 1)))
		return s;
	snprintf(file, sizeof file, "cie_illum_%s_5nm", name);
	return find(file, 1);
}

double ps_cie_spectrum_at(const struct ps_spectrum *s, double nm)
{
	double x = (nm - s->start) / s->step;
	int i;
	if (x < 0 || x > s->n - 1)
		return 0.0;
	i = (int)x;
	if (i >= s->n - 1)
		return s->v[s->n - 1];
	return s->v[i] + (x - i) * (s->v[i + 1] - s->v[i]);
}
