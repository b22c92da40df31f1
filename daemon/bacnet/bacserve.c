/* SPDX-License-Identifier: ISC */
/* The BACnet/IP server's protocol (bacserve.h).  Numbers from ANSI/ASHRAE
 * 135: BVLL Annex J, NPDU clause 6, APDU clause 20, the enumerations of
 * clause 21. */
#include "bacserve.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bacobj.h"
#include "bactag.h"

/* reject and abort reasons (clause 18.8, 18.9) */
enum { R_INVALID_TAG = 4, R_MISSING_PARAMETER = 5, R_TOO_MANY_ARGUMENTS = 7, R_UNRECOGNIZED_SERVICE = 9 };
enum { A_SEGMENTATION_NOT_SUPPORTED = PSD_BACSEG_SEGMENTATION_NOT_SUPPORTED };

/* services (BACnetConfirmedServiceChoice, BACnetUnconfirmedServiceChoice) */
enum {
	S_COV_NOTIFICATION = 1,
	S_SUBSCRIBE_COV = 5,
	S_READ_PROPERTY = 12,
	S_READ_PROPERTY_MULTIPLE = 14,
	S_WRITE_PROPERTY = 15
};
enum { U_I_AM = 0, U_I_HAVE = 1, U_COV_NOTIFICATION = 2, U_WHO_HAS = 7, U_WHO_IS = 8 };

/* ---- the APDU ------------------------------------------------------------ */

struct req {
	const uint8_t *p; /* the service's parameters */
	size_t n;
	uint8_t invoke;
	uint8_t service;
};

static void put_error(struct psd_bacbuf *b, const struct req *q, uint32_t ec, uint32_t code)
{
	uint8_t h[3] = { 0x50, q->invoke, q->service };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
	psd_bactag_put_enum(b, -1, ec);
	psd_bactag_put_enum(b, -1, code);
}

static void put_reject(struct psd_bacbuf *b, uint8_t invoke, uint8_t reason)
{
	uint8_t h[3] = { 0x60, invoke, reason };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
}

static void put_abort(struct psd_bacbuf *b, uint8_t invoke, uint8_t reason)
{
	uint8_t h[3] = { 0x71 /* abort, sent by the server */, invoke, reason };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
}

/* Read a context tag `num` at *pos: 0 found, 1 absent (another tag or the
 * end), -1 malformed. */
static int ctx_tag(const struct req *q, size_t *pos, uint32_t num, struct psd_bactag *t)
{
	if (*pos >= q->n)
		return 1;
	if (psd_bactag_peek(q->p, q->n, *pos, t) != 0)
		return -1;
	if (!t->context || t->number != num || t->opening || t->closing)
		return 1;
	return psd_bactag_read(q->p, q->n, pos, t);
}

/* A required [num] unsigned or object identifier: 0, or a reject reason. */
static int need_unsigned(const struct req *q, size_t *pos, uint32_t num, uint32_t *v)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc < 0)
		return R_INVALID_TAG;
	if (rc > 0)
		return *pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG;
	return psd_bactag_unsigned(&t, v) == 0 ? 0 : R_INVALID_TAG;
}

static int need_objectid(const struct req *q, size_t *pos, uint32_t num, uint32_t *type, uint32_t *inst)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc < 0)
		return R_INVALID_TAG;
	if (rc > 0)
		return *pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG;
	return psd_bactag_objectid(&t, type, inst) == 0 ? 0 : R_INVALID_TAG;
}

/* An optional [num] unsigned: 0 absent, 1 present, -1 malformed. */
static int opt_unsigned(const struct req *q, size_t *pos, uint32_t num, uint32_t *v)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc != 0)
		return rc < 0 ? -1 : 0;
	return psd_bactag_unsigned(&t, v) == 0 ? 1 : -1;
}

/* The head of a ReadProperty or WriteProperty: [0] object, [1] property,
 * [2] optional array index; with the object it names. */
struct target {
	uint32_t type, inst, prop, idx;
	int has_idx;
	struct psd_bacobj o;
};

/* Decode the head at *pos into t: 0, or a reject reason. */
static int decode_target(const struct req *q, size_t *pos, struct target *t)
{
	int rc;
	if ((rc = need_objectid(q, pos, 0, &t->type, &t->inst)) || (rc = need_unsigned(q, pos, 1, &t->prop)))
		return rc;
	t->idx = 0;
	if ((t->has_idx = opt_unsigned(q, pos, 2, &t->idx)) < 0)
		return R_INVALID_TAG;
	return 0;
}

/* The object t names, and its property: 0, or -1 with the Error
 * (unknown-object, unknown-property) written. */
static int resolve_target(const struct psd_bacserve_model *m, const struct req *q, struct target *t,
                          struct psd_bacbuf *b)
{
	if (psd_bacobj_find(m, t->type, t->inst, &t->o) != 0) {
		put_error(b, q, EC_OBJECT, E_UNKNOWN_OBJECT);
		return -1;
	}
	if (!psd_bacobj_has(&t->o, t->prop)) { /* ALL, REQUIRED, OPTIONAL too: RPM only (15.5.1.1.2) */
		put_error(b, q, EC_PROPERTY, E_UNKNOWN_PROPERTY);
		return -1;
	}
	return 0;
}

static void read_property(const struct psd_bacserve_model *m, const struct req *q, struct psd_bacbuf *b)
{
	size_t pos = 0, mark;
	uint32_t ec, code;
	int rc;
	struct target t;
	if ((rc = decode_target(q, &pos, &t))) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (resolve_target(m, q, &t, b) != 0)
		return;
	{
		uint8_t h[3] = { 0x30, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
	psd_bactag_put_objectid(b, 0, t.o.type, t.o.instance);
	psd_bactag_put_enum(b, 1, t.prop);
	if (t.has_idx)
		psd_bactag_put_unsigned(b, 2, t.idx);
	psd_bactag_open(b, 3);
	mark = b->len;
	if (psd_bacobj_read(m, &t.o, t.prop, t.has_idx, t.idx, b, &ec, &code) != 0) {
		b->len = mark;
		put_error(b, q, ec, code);
		return;
	}
	psd_bactag_close(b, 3);
}

/* One ReadAccessResult's element: [2] property, [3] index, [4] value or [5] error. */
static void rpm_one(const struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop,
                    int has_idx, uint32_t idx, struct psd_bacbuf *b)
{
	uint32_t ec = EC_OBJECT, code = E_UNKNOWN_OBJECT;
	size_t mark;
	psd_bactag_put_enum(b, 2, prop);
	if (has_idx)
		psd_bactag_put_unsigned(b, 3, idx);
	psd_bactag_open(b, 4);
	mark = b->len;
	if (o && psd_bacobj_read(m, o, prop, has_idx, idx, b, &ec, &code) == 0) {
		psd_bactag_close(b, 4);
		return;
	}
	b->len = mark - 1; /* the opening [4] is one octet */
	psd_bactag_open(b, 5);
	psd_bactag_put_enum(b, -1, ec);
	psd_bactag_put_enum(b, -1, code);
	psd_bactag_close(b, 5);
}

static void read_property_multiple(const struct psd_bacserve_model *m, const struct req *q,
                                   struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint8_t h[3] = { 0x30, q->invoke, q->service };
	psd_bactag_put_raw(b, h, 3);
	if (q->n == 0) {
		put_reject(b, q->invoke, R_MISSING_PARAMETER);
		return;
	}
	while (pos < q->n) {
		uint32_t type, inst;
		struct psd_bactag t;
		struct psd_bacobj o;
		int known, rc, nprop = 0;
		if ((rc = need_objectid(q, &pos, 0, &type, &inst))) {
			put_reject(b, q->invoke, (uint8_t)rc);
			return;
		}
		if (psd_bactag_read(q->p, q->n, &pos, &t) != 0 || !t.context || !t.opening || t.number != 1) {
			put_reject(b, q->invoke, R_INVALID_TAG);
			return;
		}
		known = psd_bacobj_find(m, type, inst, &o) == 0;
		psd_bactag_put_objectid(b, 0, known ? o.type : type, known ? o.instance : inst);
		psd_bactag_open(b, 1);
		for (;;) {
			uint32_t prop, idx = 0;
			int has_idx;
			if (psd_bactag_peek(q->p, q->n, pos, &t) != 0) {
				put_reject(b, q->invoke, pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG);
				return;
			}
			if (t.context && t.closing && t.number == 1) {
				psd_bactag_read(q->p, q->n, &pos, &t);
				break;
			}
			if ((rc = need_unsigned(q, &pos, 0, &prop))) {
				put_reject(b, q->invoke, (uint8_t)rc);
				return;
			}
			if ((has_idx = opt_unsigned(q, &pos, 1, &idx)) < 0) {
				put_reject(b, q->invoke, R_INVALID_TAG);
				return;
			}
			nprop++;
			if ((prop == P_ALL || prop == P_REQUIRED || prop == P_OPTIONAL) && known) {
				for (size_t i = 0; i < o.nprops; i++)
					if (prop == P_ALL ||
					    (prop == P_REQUIRED) == (o.props[i].required == 1))
						rpm_one(m, &o, o.props[i].id, 0, 0, b);
			} else {
				rpm_one(m, known ? &o : NULL, prop, has_idx, idx, b);
			}
		}
		if (nprop == 0) { /* the list of property references may not be empty */
			put_reject(b, q->invoke, R_MISSING_PARAMETER);
			return;
		}
		psd_bactag_close(b, 1);
	}
}

/* An optional [num] REAL: 0 absent, 1 present, -1 malformed. */
static int opt_real(const struct req *q, size_t *pos, uint32_t num, float *v)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc != 0)
		return rc < 0 ? -1 : 0;
	return psd_bactag_real(&t, v) == 0 ? 1 : -1;
}

/* Set priority prio (1-16) of zone's array to level (NAN: relinquish) and
 * apply it: 0, or -1 with the Error written and the array as it was. */
static int set_priority(struct psd_bacserve_model *m, const struct req *q, size_t zone, uint32_t prio, double level,
                        struct psd_bacbuf *b)
{
	struct psd_bacserve_zone *z = &m->zone[zone];
	double was;
	if (prio < 1 || prio > PSD_BACSERVE_PRIORITIES) {
		put_error(b, q, EC_SERVICES, E_PARAMETER_OUT_OF_RANGE);
		return -1;
	}
	if (prio == 6) { /* reserved for minimum on/off (19.2.1.1) */
		put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
		return -1;
	}
	was = z->prio[prio - 1];
	/* a BMS re-commanding what it commanded (each second, say) changes
	 * nothing: acknowledged without a control step, a log line or frames */
	if (was == level || (isnan(was) && isnan(level)))
		return 0;
	z->prio[prio - 1] = level;
	if (m->apply && m->apply(m->user, zone) != 0) {
		z->prio[prio - 1] = was;
		put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
		return -1;
	}
	return 0;
}

/* A Lighting_Command (BACnetLightingCommand, 12.54.8) in q->p[from..to):
 * [0] operation, [1] target level, [2] ramp rate, [3] step increment,
 * [4] fade time, [5] priority.  The operations psensd does (PICS): fade-to
 * and ramp-to (the target level; psensd's lamps fade at their own rate),
 * step-up, step-down, step-on, step-off (by the step increment, 1 %
 * unless given) and stop (the level the lamps have reached); each a level
 * at the command's priority (default 16), as a Present_Value write. */
static void lighting_command(struct psd_bacserve_model *m, const struct req *q, const struct psd_bacobj *o,
                             size_t from, size_t to, struct psd_bacbuf *b)
{
	struct req v = { q->p + from, to - from, q->invoke, q->service };
	struct psd_bacserve_zone *z = &m->zone[o->zone];
	size_t pos = 0;
	uint32_t op, prio = 16, fade = 0;
	float target = NAN, ramp = 0, step = 1.0f;
	double level = z->level, now_level;
	if (need_unsigned(&v, &pos, 0, &op) != 0 || opt_real(&v, &pos, 1, &target) < 0 ||
	    opt_real(&v, &pos, 2, &ramp) < 0 || opt_real(&v, &pos, 3, &step) < 0 ||
	    opt_unsigned(&v, &pos, 4, &fade) < 0 || opt_unsigned(&v, &pos, 5, &prio) < 0 || pos != v.n) {
		put_error(b, q, EC_PROPERTY, E_INVALID_DATA_TYPE);
		return;
	}
	(void)ramp, (void)fade;
	if (!(step > 0.0f && step <= 100.0f)) {
		put_error(b, q, EC_PROPERTY, E_VALUE_OUT_OF_RANGE);
		return;
	}
	switch (op) {
	case LC_FADE_TO:
	case LC_RAMP_TO:
		if (!(target >= 0.0f && target <= 100.0f)) {
			put_error(b, q, EC_PROPERTY, E_VALUE_OUT_OF_RANGE);
			return;
		}
		now_level = target;
		break;
	case LC_STEP_UP: now_level = level > 0 ? fmin(100, level + step) : level; break;
	case LC_STEP_DOWN: now_level = level > 0 ? fmax(1, level - step) : level; break;
	case LC_STEP_ON: now_level = fmin(100, level + step); break;
	case LC_STEP_OFF: now_level = level - step >= 1 ? level - step : 0; break;
	case LC_STOP: now_level = psd_bacobj_actual_level(m, o); break;
	default: /* none, the warnings, proprietary ones */
		put_error(b, q, EC_PROPERTY, op > LC_STOP ? E_VALUE_OUT_OF_RANGE : E_NOT_SUPPORTED);
		return;
	}
	if (set_priority(m, q, o->zone, prio, now_level, b) != 0)
		return;
	z->lc_op = op, z->lc_target = now_level, z->lc_prio = prio;
	{
		uint8_t h[3] = { 0x20, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
}

static void write_property(struct psd_bacserve_model *m, const struct req *q, struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint32_t prio = 16;
	int rc, is_null = 0;
	float v = 0;
	struct psd_bactag t, val = { 0 };
	struct target w;
	size_t vstart, vend = 0;
	if ((rc = decode_target(q, &pos, &w)) != 0 && rc != R_INVALID_TAG) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	/* a malformed tag, or no [3] value: missing when the request ended */
	if (rc || psd_bactag_read(q->p, q->n, &pos, &t) != 0 || !t.context || !t.opening || t.number != 3) {
		put_reject(b, q->invoke, pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG);
		return;
	}
	vstart = pos;
	/* the value, vstart up to its [3] closing at vend */
	{
		int depth = 0;
		for (;;) {
			size_t at = pos;
			if (psd_bactag_read(q->p, q->n, &pos, &t) != 0) {
				put_reject(b, q->invoke, R_INVALID_TAG);
				return;
			}
			if (t.context && t.opening) {
				depth++;
			} else if (t.context && t.closing && depth-- == 0) {
				if (t.number != 3) {
					put_reject(b, q->invoke, R_INVALID_TAG);
					return;
				}
				vend = at;
				break;
			}
		}
	}
	{ /* one application-tagged datum, or (judged below as the wrong type) not */
		size_t p2 = vstart;
		if (psd_bactag_read(q->p, vend, &p2, &val) != 0 || p2 != vend)
			val.context = 1;
	}
	if ((rc = opt_unsigned(q, &pos, 4, &prio)) < 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (resolve_target(m, q, &w, b) != 0)
		return;
	if (w.o.type == PSD_BAC_AV || w.o.type == PSD_BAC_BV || w.o.type == PSD_BAC_MSV) {
		uint32_t ec, code;
		if (psd_bacobj_write_value(m, &w.o, w.prop, w.has_idx, prio, &val, &ec, &code) != 0) {
			put_error(b, q, ec, code);
		} else {
			uint8_t h[3] = { 0x20, q->invoke, q->service };
			psd_bactag_put_raw(b, h, 3);
		}
		return;
	}
	if (w.o.type != PSD_BAC_LO || (w.prop != P_PRESENT_VALUE && w.prop != P_LIGHTING_COMMAND) ||
	    !(m->writes & 1)) {
		put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
		return;
	}
	if (w.has_idx) {
		put_error(b, q, EC_PROPERTY, E_NOT_AN_ARRAY);
		return;
	}
	if (w.prop == P_LIGHTING_COMMAND) { /* its priority is its own [5], not the service's */
		lighting_command(m, q, &w.o, vstart, vend, b);
		return;
	}
	if (prio < 1 || prio > PSD_BACSERVE_PRIORITIES) {
		put_error(b, q, EC_SERVICES, E_PARAMETER_OUT_OF_RANGE);
		return;
	}
	if (!val.context && val.number == PSD_BACTAG_NULL && val.len == 0)
		is_null = 1;
	else if (val.context || val.number != PSD_BACTAG_REAL || psd_bactag_real(&val, &v) != 0) {
		put_error(b, q, EC_PROPERTY, E_INVALID_DATA_TYPE);
		return;
	}
	if (!is_null && !(v >= 0.0f && v <= 100.0f)) {
		put_error(b, q, EC_PROPERTY, E_VALUE_OUT_OF_RANGE);
		return;
	}
	if (set_priority(m, q, w.o.zone, prio, is_null ? NAN : (double)v, b) != 0)
		return;
	{
		uint8_t h[3] = { 0x20, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
}

/* SubscribeCOV (13.14): a subscription made, renewed or cancelled. */
static void subscribe_cov(struct psd_bacserve_model *m, const struct req *q, const uint8_t *src,
                          const uint8_t *npdu, size_t npdu_len, struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint32_t pid, type, inst, life = 0;
	int rc, has_conf, has_life, confirmed = 0;
	struct psd_bactag t;
	struct psd_bacserve_sub *free_slot = NULL, *s = NULL;
	struct psd_bacobj o;
	size_t mine = 0;
	if ((rc = need_unsigned(q, &pos, 0, &pid)) || (rc = need_objectid(q, &pos, 1, &type, &inst))) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	if ((has_conf = ctx_tag(q, &pos, 2, &t)) < 0 || (has_conf == 0 && (t.len != 1 || t.data[0] > 1))) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	has_conf = has_conf == 0;
	if (has_conf)
		confirmed = t.data[0];
	if ((has_life = opt_unsigned(q, &pos, 3, &life)) < 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (has_life && !has_conf) {
		put_reject(b, q->invoke, R_MISSING_PARAMETER);
		return;
	}
	if (npdu_len > sizeof s->npdu)
		return;
	for (size_t i = 0; i < PSD_BACSERVE_SUBS; i++) {
		struct psd_bacserve_sub *x = &m->sub[i];
		if (!x->used) {
			if (!free_slot)
				free_slot = x;
		} else if (x->pid == pid && x->type == type && x->instance == inst &&
		           memcmp(x->addr, src, 6) == 0) {
			s = x;
		}
		/* the host's share: its IPv4 address, whichever port it sends from */
		mine += x->used && memcmp(x->addr, src, 4) == 0;
	}
	if (!has_conf) { /* a cancellation: done whether or not it was there */
		if (s)
			s->used = 0;
	} else {
		if (psd_bacobj_find(m, type, inst, &o) != 0) {
			put_error(b, q, EC_OBJECT, E_UNKNOWN_OBJECT);
			return;
		}
		if (o.type == PSD_BAC_DEVICE) {
			put_error(b, q, EC_OBJECT, E_NOT_SUPPORTED);
			return;
		}
		if (!s && (mine >= PSD_BACSERVE_SUBS_PER_SOURCE || !(s = free_slot))) {
			put_error(b, q, EC_RESOURCES, E_NO_SPACE_TO_ADD);
			return;
		}
		*s = (struct psd_bacserve_sub){ .used = 1,
			                        .pid = pid,
			                        .type = o.type,
			                        .instance = o.instance,
			                        .confirmed = confirmed,
			                        .npdu_len = npdu_len,
			                        .expires = life ? m->now + life : 0 };
		memcpy(s->addr, src, 6);
		memcpy(s->npdu, npdu, npdu_len);
	}
	{
		uint8_t h[3] = { 0x20, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
}

/* Whole seconds left, rounded up; a sum's last bit (300.000000001) is not
 * a second more. */
static uint32_t remaining(double left)
{
	return left > 1e-6 ? (uint32_t)ceil(left - 1e-6) : 0;
}

int psd_bacserve_cov(struct psd_bacserve_model *m, uint8_t *out, struct psd_bacserve_reply *r)
{
	memset(r, 0, sizeof *r);
	for (size_t i = 0; i < PSD_BACSERVE_SUBS; i++) {
		struct psd_bacserve_sub *s = &m->sub[i];
		struct psd_bacbuf b;
		struct psd_bacobj o;
		float pv;
		int fault;
		if (!s->used)
			continue;
		if ((s->expires > 0 && m->now >= s->expires) ||
		    psd_bacobj_find(m, s->type, s->instance, &o) != 0) {
			s->used = 0; /* its lifetime ended, or its zone left at a reload */
			continue;
		}
		pv = psd_bacobj_present_value(m, &o);
		fault = psd_bacobj_fault(m, &o);
		if (s->sent && fault == s->last_fault &&
		    (pv == s->last_pv || (isnan(pv) && isnan(s->last_pv)) ||
		     fabsf(pv - s->last_pv) < psd_bacobj_cov_increment(&o)))
			continue;
		s->sent = 1, s->last_pv = pv, s->last_fault = fault;
		out[0] = 0x81, out[1] = 0x0a;
		memcpy(out + 4, s->npdu, s->npdu_len);
		b = (struct psd_bacbuf){ out + 4 + s->npdu_len, PSD_BACSERVE_MAX_APDU, 0, 0 };
		if (s->confirmed) {
			uint8_t h[4] = { 0x00, 0x05, m->invoke++, S_COV_NOTIFICATION };
			psd_bactag_put_raw(&b, h, 4);
		} else {
			uint8_t h[2] = { 0x10, U_COV_NOTIFICATION };
			psd_bactag_put_raw(&b, h, 2);
		}
		psd_bactag_put_unsigned(&b, 0, s->pid);
		psd_bactag_put_objectid(&b, 1, PSD_BAC_DEVICE, m->device);
		psd_bactag_put_objectid(&b, 2, s->type, s->instance);
		psd_bactag_put_unsigned(&b, 3, s->expires > 0 ? remaining(s->expires - m->now) : 0);
		psd_bactag_open(&b, 4);
		psd_bactag_put_enum(&b, 0, P_PRESENT_VALUE);
		psd_bactag_open(&b, 2);
		psd_bacobj_put_present_value(m, &o, &b);
		psd_bactag_close(&b, 2);
		psd_bactag_put_enum(&b, 0, P_STATUS_FLAGS);
		psd_bactag_open(&b, 2);
		psd_bacobj_put_status_flags(&b, fault);
		psd_bactag_close(&b, 2);
		psd_bactag_close(&b, 4);
		r->len = 4 + s->npdu_len + b.len;
		out[2] = (uint8_t)(r->len >> 8), out[3] = (uint8_t)r->len;
		r->to = PSD_BACSERVE_TO_ADDRESS;
		memcpy(r->addr, s->addr, 6);
		return 1;
	}
	return 0;
}

/* Who-Is: 1 when this device is in its range (or it has none), 0 not,
 * -1 malformed. */
static int who_is_me(const struct psd_bacserve_model *m, const uint8_t *p, size_t n)
{
	struct req q = { p, n, 0, 0 };
	size_t pos = 0;
	uint32_t lo, hi;
	if (n == 0)
		return 1;
	if (need_unsigned(&q, &pos, 0, &lo) || need_unsigned(&q, &pos, 1, &hi) || pos != n ||
	    lo > MAX_INSTANCE || hi > MAX_INSTANCE)
		return -1;
	return m->device >= lo && m->device <= hi;
}

/* Who-Has (16.9): the I-Have for the object named by identifier or by
 * name, when this device is in the range (or there is none); nothing
 * when psensd has no such object or the request is malformed. */
static void who_has(const struct psd_bacserve_model *m, const uint8_t *p, size_t n, struct psd_bacbuf *b)
{
	struct req q = { p, n, 0, 0 };
	size_t pos = 0;
	uint32_t lo, hi, type, inst;
	int has_lo, has_hi;
	struct psd_bactag t;
	struct psd_bacobj o;
	char name[128];
	if ((has_lo = opt_unsigned(&q, &pos, 0, &lo)) < 0 || (has_hi = opt_unsigned(&q, &pos, 1, &hi)) < 0 ||
	    has_lo != has_hi || (has_lo && (lo > MAX_INSTANCE || hi > MAX_INSTANCE)))
		return;
	if (has_lo && !(m->device >= lo && m->device <= hi))
		return;
	if (psd_bactag_read(p, n, &pos, &t) != 0 || pos != n || !t.context || t.opening || t.closing)
		return;
	if (t.number == 2) {
		if (psd_bactag_objectid(&t, &type, &inst) != 0 || psd_bacobj_find(m, type, inst, &o) != 0 ||
		    (o.type == PSD_BAC_DEVICE && inst != m->device))
			return;
	} else if (t.number == 3) { /* a character string in UTF-8 (set 0) */
		size_t i, count = psd_bacobj_count(m);
		if (t.len < 1 || t.data[0] != 0)
			return;
		for (i = 0; i < count; i++) {
			psd_bacobj_at(m, i, &o);
			psd_bacobj_name(m, &o, name, sizeof name);
			if (strlen(name) == t.len - 1 && memcmp(name, t.data + 1, t.len - 1) == 0)
				break;
		}
		if (i == count)
			return;
	} else {
		return;
	}
	{
		uint8_t h[2] = { 0x10, U_I_HAVE };
		psd_bactag_put_raw(b, h, 2);
	}
	psd_bacobj_name(m, &o, name, sizeof name);
	psd_bactag_put_objectid(b, -1, PSD_BAC_DEVICE, m->device);
	psd_bactag_put_objectid(b, -1, o.type, o.instance);
	psd_bactag_put_string(b, -1, name);
}

static void put_i_am(const struct psd_bacserve_model *m, struct psd_bacbuf *b)
{
	uint8_t h[2] = { 0x10, U_I_AM };
	psd_bactag_put_raw(b, h, 2);
	psd_bactag_put_objectid(b, -1, PSD_BAC_DEVICE, m->device);
	psd_bactag_put_unsigned(b, -1, PSD_BACSERVE_MAX_APDU);
	psd_bactag_put_enum(b, -1, 1); /* segmented-transmit */
	psd_bactag_put_unsigned(b, -1, m->vendor_id);
}

size_t psd_bacserve_i_am(const struct psd_bacserve_model *m, uint8_t fn, uint8_t *out)
{
	struct psd_bacbuf b = { out + 6, PSD_BACSERVE_MAX_APDU, 0, 0 };
	size_t len;
	put_i_am(m, &b);
	len = 6 + b.len;
	out[0] = 0x81, out[1] = fn, out[2] = (uint8_t)(len >> 8), out[3] = (uint8_t)len;
	out[4] = 1, out[5] = 0; /* NPDU version 1, no addresses, no reply expected */
	return len;
}

/* The largest APDU the asker accepts (20.1.2.5); reserved codes: the least. */
static size_t max_apdu(uint8_t code)
{
	static const size_t len[6] = { 50, 128, 206, 480, 1024, 1476 };
	return code < 6 ? len[code] : 50;
}

/* The confirmed service q into b. */
static void service(struct psd_bacserve_model *m, const struct req *q, const uint8_t *src, const uint8_t *npdu,
                    size_t npdu_len, struct psd_bacbuf *b)
{
	switch (q->service) {
	case S_READ_PROPERTY: read_property(m, q, b); break;
	case S_READ_PROPERTY_MULTIPLE: read_property_multiple(m, q, b); break;
	case S_WRITE_PROPERTY: write_property(m, q, b); break;
	case S_SUBSCRIBE_COV: subscribe_cov(m, q, src, npdu, npdu_len, b); break;
	default: put_reject(b, q->invoke, R_UNRECOGNIZED_SERVICE); break;
	}
}

/* A confirmed request whose asker takes a segmented answer (SA): the
 * answer built whole in the segmenter's scratch buffer, then sent as it
 * is when it fits the asker's max-APDU, else in segments (nothing in b
 * then), else the Abort the segmenter names.  -1: no scratch memory. */
static int segmentable(struct psd_bacserve_model *m, const struct req *q, uint8_t accepts, const uint8_t *src,
                       const uint8_t *npdu, size_t npdu_len, struct psd_bacbuf *b)
{
	uint8_t *scratch = psd_bacseg_scratch(&m->seg);
	struct psd_bacbuf big = { scratch, PSD_BACSEG_MAX_LEN, 0, 0 };
	int rc;
	if (!scratch)
		return -1;
	service(m, q, src, npdu, npdu_len, &big);
	if (big.overflow) {
		put_abort(b, q->invoke, PSD_BACSEG_APDU_TOO_LONG);
	} else if (big.len <= max_apdu(accepts & 15) && big.len <= b->cap) {
		b->len = 0;
		psd_bactag_put_raw(b, scratch, big.len);
	} else if (big.len < 3 || scratch[0] != 0x30) { /* only a ComplexACK is long */
		put_abort(b, q->invoke, A_SEGMENTATION_NOT_SUPPORTED);
	} else if ((rc = psd_bacseg_start(&m->seg, src, npdu, npdu_len, accepts, scratch, big.len, m->now))) {
		put_abort(b, q->invoke, (uint8_t)rc);
	} else {
		b->len = 0; /* queued: psd_bacseg_next sends it */
	}
	return 0;
}

/* The APDU apdu[0..n): the reply's APDU into b (nothing: b->len 0). */
static void apdu(struct psd_bacserve_model *m, const uint8_t *a, size_t n, int broadcast, const uint8_t *src,
                 const uint8_t *npdu, size_t npdu_len, struct psd_bacbuf *b)
{
	unsigned type;
	struct req q;
	size_t cap = b->cap;
	if (n < 2)
		return;
	type = a[0] >> 4;
	if (type == 1) { /* unconfirmed request */
		if (a[1] == U_WHO_IS && who_is_me(m, a + 2, n - 2) == 1)
			put_i_am(m, b);
		else if (a[1] == U_WHO_HAS) {
			who_has(m, a + 2, n - 2, b);
		}
		return;
	}
	if (broadcast)
		return;
	if (type == 4) { /* a SegmentACK for an answer in segments */
		int rc = psd_bacseg_ack(&m->seg, src, npdu, npdu_len, a, n, m->now);
		if (rc > 0 && n >= 2)
			put_abort(b, a[1], (uint8_t)rc);
		return;
	}
	if (type == 7) { /* an Abort from a client ends its answer's transaction */
		if (n == 3 && !(a[0] & 0x01))
			psd_bacseg_cancel(&m->seg, src, npdu, npdu_len, a[1]);
		return;
	}
	/* only a confirmed request is answered; one sent to everyone is not
	 * (no amplified replies to a forged broadcast) */
	if (type != 0 || n < 3)
		return;
	if (a[0] & 0x08) { /* segmented: refused (20.1.2.1), whatever follows */
		put_abort(b, a[2], A_SEGMENTATION_NOT_SUPPORTED);
		return;
	}
	if (n < 4)
		return;
	q = (struct req){ a + 4, n - 4, a[2], a[3] };
	if (psd_bacseg_busy(&m->seg, src, npdu, npdu_len, q.invoke))
		return; /* a repeat of a request being answered in segments */
	if ((a[0] & 0x02) && segmentable(m, &q, a[1], src, npdu, npdu_len, b) == 0)
		return;
	if (max_apdu(a[1] & 15) < cap)
		b->cap = max_apdu(a[1] & 15);
	service(m, &q, src, npdu, npdu_len, b);
	if (b->overflow) { /* longer than the asker takes, and it takes no segments */
		b->cap = cap;
		put_abort(b, q.invoke, A_SEGMENTATION_NOT_SUPPORTED);
	}
	b->cap = cap;
}

/* ---- BVLL and NPDU ----------------------------------------------------- */

void psd_bacserve_handle(struct psd_bacserve_model *m, const uint8_t *in, size_t n, const uint8_t src[6],
                         int broadcast, uint8_t *out, struct psd_bacserve_reply *r)
{
	size_t pos, snet_at = 0, h;
	unsigned fn, ctrl;
	struct psd_bacbuf b;
	memset(r, 0, sizeof *r);
	if (n < 4 || n > PSD_BACSERVE_MAX_PACKET || in[0] != 0x81 || ((size_t)in[2] << 8 | in[3]) != n)
		return;
	fn = in[1];
	pos = 4;
	switch (fn) {
	case 0x0a: /* Original-Unicast-NPDU */ r->to = PSD_BACSERVE_TO_SENDER; break;
	case 0x0b: /* Original-Broadcast-NPDU */
		r->to = PSD_BACSERVE_TO_SENDER;
		broadcast = 1;
		break;
	case 0x04: /* Forwarded-NPDU: a BBMD passes on a broadcast from addr */
		if (n < 10)
			goto none;
		memcpy(r->addr, in + 4, 6);
		src = r->addr;
		r->to = PSD_BACSERVE_TO_ADDRESS;
		broadcast = 1;
		pos = 10;
		break;
	case 0x01:
	case 0x02:
	case 0x05:
	case 0x06:
	case 0x08:
	case 0x09: {
		/* a BBMD's or foreign device's function psensd does not do: the
		 * BVLC-Result NAK for it (J.2.1), 0x0010 to 0x0060 */
		static const uint8_t nak[10] = {
			[1] = 0x10, [2] = 0x20, [5] = 0x30, [6] = 0x40, [8] = 0x50, [9] = 0x60
		};
		if (broadcast)
			return;
		out[0] = 0x81, out[1] = 0x00, out[2] = 0, out[3] = 6, out[4] = 0, out[5] = nak[fn];
		r->to = PSD_BACSERVE_TO_SENDER;
		r->len = 6;
		return;
	}
	default: /* results, acknowledgements, secure BVLL: nothing to say */ return;
	}
	/* the NPDU (clause 6.2) */
	if (n - pos < 2 || in[pos] != 1)
		goto none;
	ctrl = in[pos + 1];
	pos += 2;
	if (ctrl & 0x80 || ctrl & 0x50) /* a network-layer message, or reserved bits */
		goto none;
	if (ctrl & 0x20) { /* DNET: for another network unless a global broadcast */
		if (n - pos < 3 || ((unsigned)in[pos] << 8 | in[pos + 1]) != 0xffff)
			goto none;
		if (n - pos - 3 < in[pos + 2])
			goto none;
		pos += 3 + in[pos + 2];
		broadcast = 1;
	}
	if (ctrl & 0x08) { /* SNET: from another network, through a router */
		if (n - pos < 3 || in[pos + 2] == 0 || n - pos - 3 < in[pos + 2] || in[pos + 2] > 8 ||
		    ((unsigned)in[pos] << 8 | in[pos + 1]) == 0xffff)
			goto none;
		snet_at = pos;
		pos += 3 + in[pos + 2];
	}
	if (ctrl & 0x20) { /* the hop count */
		if (pos >= n)
			goto none;
		pos++;
	}
	/* the reply's NPDU: to the source network's address when it came
	 * through a router */
	out[0] = 0x81, out[1] = 0x0a;
	out[4] = 1;
	h = 6;
	if (snet_at) {
		size_t slen = in[snet_at + 2];
		out[5] = 0x20;
		memcpy(out + 6, in + snet_at, 3 + slen);
		h += 3 + slen;
		out[h++] = 255; /* hop count */
	} else {
		out[5] = 0;
	}
	b = (struct psd_bacbuf){ out + h, PSD_BACSERVE_MAX_APDU, 0, 0 };
	apdu(m, in + pos, n - pos, broadcast, src, out + 4, h - 4, &b);
	if (b.len == 0 || b.overflow)
		goto none;
	r->len = h + b.len;
	out[2] = (uint8_t)(r->len >> 8), out[3] = (uint8_t)r->len;
	return;
none:
	r->to = PSD_BACSERVE_NONE;
	r->len = 0;
}
