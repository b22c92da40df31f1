/* SPDX-License-Identifier: ISC */
#include "picview.h"

#include <stdio.h>

int ps_picview_fisheye(const struct ps_picture *pic, const char *path, struct ps_view *v,
                       int *assumed, struct ps_err *e)
{
	char where[600];
	snprintf(where, sizeof where, "%s: VIEW", path);
	if (assumed)
		*assumed = !pic->view;
	if (!pic->view) {
		ps_view_default_fisheye(v);
	} else {
		/* VIEW= options apply on top of Radiance's default view */
		ps_view_default(v);
		if (ps_view_parse(v, pic->view, where, e) != 0)
			return -1;
	}
	return ps_view_check_fisheye(v, where, e);
}
