/* SPDX-License-Identifier: ISC */
/* The web console in a build without libmicrohttpd (WITH_WEB=no, or auto
 * without it): the [web] section is still read and judged, and a file that
 * has one is refused at start rather than run without its console.  The
 * row never starts, so it needs no other hook. */
#include <stddef.h>

#include "config.h"
#include "errbuf.h"
#include "web.h"

static int wanted(const struct psd_config *cf)
{
	return cf->web.enabled;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	(void)env;
	psd_errbuf(err, errlen, "[web]: this psensd was built without the web console (WITH_WEB=no or no libmicrohttpd)");
	return NULL;
}

static void stop(void *fe)
{
	(void)fe;
}

const struct psd_frontend psd_web_frontend = {
	.name = "web",
	.refused = "the web console cannot start",
	.wanted = wanted,
	.start = start,
	.stop = stop,
};
