/* SPDX-License-Identifier: ISC */
/* The report's text boxes: every text the document draws records the box
 * it covers (page, left, top, right, bottom in points), so a test can check
 * that no two texts on a page overlap and that pages are filled. */
#ifndef PSD_TEXTBOX_H
#define PSD_TEXTBOX_H

#include <stddef.h>

struct psd_textbox {
	int page;
	double x0, y0, x1, y1;
	char text[96];            /* the start of the text, for messages and tests */
};

struct psd_textboxes {
	struct psd_textbox *box;
	size_t n, cap;
};

/* Record a box (x0 <= x1, y0 <= y1 in any order given).  -1 (ENOMEM). */
int psd_textbox_add(struct psd_textboxes *r, int page, double x0, double y0, double x1, double y1,
                      const char *text);
/* The first pair of boxes on one page that overlap by more than slack
 * points in both directions: 1 with their indexes, 0 when none does. */
int psd_textbox_overlap(const struct psd_textboxes *r, double slack, size_t *i, size_t *j);
void psd_textbox_free(struct psd_textboxes *r);

#endif
