/* SPDX-License-Identifier: ISC */
/* The web console in a build without libmicrohttpd (WITH_WEB=no, or auto
 * without it): the [web] section is still read and judged, and a file that
 * has one is refused at start rather than run without its console. */
#include <stddef.h>

#include "errbuf.h"
#include "web.h"

struct psd_web *psd_web_open(const struct psd_web_conf *c, struct psd_engine *e, psd_web_request_fn fn, void *user,
                             char *err, size_t errlen)
{
	(void)c;
	(void)e;
	(void)fn;
	(void)user;
	psd_errbuf(err, errlen, "[web]: this psensd was built without the web console (WITH_WEB=no or no libmicrohttpd)");
	return NULL;
}

int psd_web_pollfd(struct psd_web *w, struct pollfd *pfd)
{
	(void)w;
	(void)pfd;
	return 0;
}

void psd_web_service(struct psd_web *w, const struct pollfd *pfd)
{
	(void)w;
	(void)pfd;
}

int psd_web_wait_ms(const struct psd_web *w)
{
	(void)w;
	return -1;
}

void psd_web_close(struct psd_web *w)
{
	(void)w;
}
