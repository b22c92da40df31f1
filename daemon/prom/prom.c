/* SPDX-License-Identifier: ISC */
#include "prom.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "engine.h"
#include "errbuf.h"
#include "log.h"
#include "points.h"
#include "replace.h"
#include "time.h"

struct prom {
	struct psd_engine *e;
	const struct psd_points *pts;
	double next;    /* the textfile's next write, monotonic s */
	int failing;    /* its writes fail (logged once until one succeeds) */
};

/* Always running: whether it writes is the engine's configuration's
 * (a reload may add [prometheus]). */
static int wanted(const struct psd_config *cf)
{
	(void)cf;
	return 1;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	struct prom *p = calloc(1, sizeof *p);
	if (!p) {
		psd_errbuf(err, errlen, "[prometheus]: %s", strerror(errno));
		return NULL;
	}
	*p = (struct prom){ .e = env->engine, .pts = env->points, .next = 0 };
	return p;
}

static const char *textfile(const struct prom *p)
{
	return p->e->cf ? p->e->cf->prom.textfile : NULL;
}

/* The point model into the textfile when its interval has passed (real
 * seconds); a failure logged once, and its end. */
static void step(void *fe, double now)
{
	struct prom *p = fe;
	const char *path = textfile(p);
	double t = psd_time_mono();
	char *text;
	if (!path || t < p->next)
		return;
	p->next = t + p->e->cf->prom.interval;
	text = psd_points_prometheus(p->pts, p->e, now);
	if (!text || ps_replace_file(path, 0644, text, strlen(text), NULL) != 0) {
		if (!p->failing++)
			psd_log_err("prometheus: %s", path);
	} else if (p->failing) {
		psd_log_info("prometheus: %s written again", path);
		p->failing = 0;
	}
	free(text);
}

static int wait_ms(const void *fe)
{
	const struct prom *p = fe;
	int w;
	if (!textfile(p))
		return -1;
	w = (int)ceil((p->next - psd_time_mono()) * 1000);
	return w < 0 ? 0 : w;
}

static void stop(void *fe)
{
	free(fe);
}

const struct psd_frontend psd_prom_frontend = {
	.name = "prometheus",
	.refused = "Prometheus cannot start",
	.wanted = wanted,
	.start = start,
	.step = step,
	.wait_ms = wait_ms,
	.stop = stop,
};
