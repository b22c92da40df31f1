/* SPDX-License-Identifier: ISC */
#include "webdoc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "annual.h"
#include "errbuf.h"
#include "report.h"

/* The file made at dir/name (made 0: making it failed) into *buf, then
 * both removed.  0 or -1 with err. */
static int take(const char *dir, const char *path, int made, unsigned char **buf, size_t *len, char *err, size_t n)
{
	struct stat st;
	FILE *fp = made ? fopen(path, "rb") : NULL;
	int rc = -1;
	*buf = NULL;
	if (fp && fstat(fileno(fp), &st) == 0 && st.st_size > 0 && (*buf = malloc((size_t)st.st_size))) {
		if (fread(*buf, 1, (size_t)st.st_size, fp) == (size_t)st.st_size) {
			*len = (size_t)st.st_size;
			rc = 0;
		} else {
			free(*buf);
			*buf = NULL;
		}
	}
	if (made && rc != 0)
		psd_errbuf(err, n, "%s cannot be read back", path);
	if (fp)
		fclose(fp);
	unlink(path);
	rmdir(dir);
	return rc;
}

int psd_webdoc_record(const struct psd_engine *e, const char *zone, unsigned char **buf, size_t *len, char *err,
                      size_t n)
{
	struct psd_report_opts ro = { .tolerance_pct = 25, .format = PSD_REPORT_PDF };
	struct psd_report_out res = { 0 };
	char dir[] = "/tmp/psensd-web.XXXXXX", path[64];
	int rc;
	if (zone && !psd_engine_zone((struct psd_engine *)e, zone))
		return psd_errbuf(err, n, "no zone '%s'", zone), PSD_WEBDOC_NONE;
	if (!e->cf->database)
		return psd_errbuf(err, n, "psensd keeps no database: the record is drawn from its log"), PSD_WEBDOC_NONE;
	if (!mkdtemp(dir))
		return psd_errbuf(err, n, "no temporary directory for the record"), -1;
	snprintf(path, sizeof path, "%s/record.pdf", dir);
	ro.dbpath = e->cf->database;
	ro.zone = zone;
	ro.config_path = e->cf->conf.path;
	ro.cf = e->cf;
	ro.written = time(NULL);
	rc = psd_report_write(&ro, path, &res, err, n);
	psd_report_out_free(&res);
	return take(dir, path, rc == 0, buf, len, err, n);
}

int psd_webdoc_year(const struct psd_engine *e, const char *zone, unsigned char **buf, size_t *len, char *err,
                    size_t n)
{
	const struct psd_zone *z = psd_engine_zone((struct psd_engine *)e, zone);
	const struct ps_results *r;
	struct psd_annual_opt o = { .dated = 1 };
	struct psd_annual *a = NULL;
	struct psd_control ctl;
	char dir[] = "/tmp/psensd-web.XXXXXX", path[64], devices[256], title[256];
	int made = 0;
	if (!z)
		return psd_errbuf(err, n, "no zone '%s'", zone), PSD_WEBDOC_NONE;
	r = z->res ? z->res : e->have_res ? &e->res : NULL;
	if (!r || !r->have_year)
		return psd_errbuf(err, n, "the zone's results have no year: give the scene a weather file "
		                  "(psscene(5), [daylight_coefficients] weather =)"), PSD_WEBDOC_NONE;
	if (!mkdtemp(dir))
		return psd_errbuf(err, n, "no temporary directory for the picture"), -1;
	snprintf(path, sizeof path, "%s/year.png", dir);
	o.period = z->zc->period;
	o.occ_start = e->cf->occ_from;
	o.occ_end = e->cf->occ_to;
	ctl = z->ctl;
	if (!(a = calloc(1, sizeof *a)) || !(o.task_img = calloc(PSD_ANNUAL_MAX_DAYS * 144, sizeof(float))) ||
	    !(o.level_img = calloc(PSD_ANNUAL_MAX_DAYS * 144, sizeof(float))))
		psd_errbuf(err, n, "out of memory");
	else if (psd_annual_devices(e->cf, z->zc, &o, devices, sizeof devices, err, n) != 0)
		;
	else if (psd_annual_run(r, &ctl, &o, a) != 0)
		psd_errbuf(err, n, "the year cannot run (no electric condition?)");
	else {
		const char *wb = strrchr(r->weather, '/');
		snprintf(title, sizeof title, "zone %s, %s, target %g lx (%s)", z->zc->name,
		         psd_control_algorithm_names[ctl.algorithm], ctl.target_lux, wb ? wb + 1 : r->weather);
		made = psd_annual_png(path, o.task_img, o.level_img, a->days, ctl.target_lux, title, err, n) == 0;
	}
	free(a);
	free(o.task_img);
	free(o.level_img);
	return take(dir, path, made, buf, len, err, n);
}
