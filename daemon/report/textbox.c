/* SPDX-License-Identifier: ISC */
#include "textbox.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int psd_textbox_add(struct psd_textboxes *r, int page, double x0, double y0, double x1, double y1,
                      const char *text)
{
	struct psd_textbox *b;
	if (r->n == r->cap) {
		size_t cap = r->cap ? 2 * r->cap : 64;
		void *p = realloc(r->box, cap * sizeof *r->box);
		if (!p) {
			errno = ENOMEM;
			return -1;
		}
		r->box = p;
		r->cap = cap;
	}
	b = &r->box[r->n++];
	b->page = page;
	b->x0 = fmin(x0, x1);
	b->x1 = fmax(x0, x1);
	b->y0 = fmin(y0, y1);
	b->y1 = fmax(y0, y1);
	snprintf(b->text, sizeof b->text, "%s", text ? text : "");
	return 0;
}

int psd_textbox_overlap(const struct psd_textboxes *r, double slack, size_t *i, size_t *j)
{
	for (size_t a = 0; a < r->n; a++)
		for (size_t b = a + 1; b < r->n; b++) {
			const struct psd_textbox *p = &r->box[a], *q = &r->box[b];
			if (p->page != q->page)
				continue;
			if (fmin(p->x1, q->x1) - fmax(p->x0, q->x0) > slack &&
			    fmin(p->y1, q->y1) - fmax(p->y0, q->y0) > slack) {
				*i = a;
				*j = b;
				return 1;
			}
		}
	return 0;
}

void psd_textbox_free(struct psd_textboxes *r)
{
	free(r->box);
	r->box = NULL;
	r->n = r->cap = 0;
}
