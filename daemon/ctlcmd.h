/* SPDX-License-Identifier: ISC */
/* The control commands' answers (daemon/ctlcmd.c): the handlers the
 * command table's rows name (cmdtab.h), each answering one request whose
 * words the table has judged with one JSON line, for the socket, the web
 * console and MQTT alike. */
#ifndef PSD_CTLCMD_H
#define PSD_CTLCMD_H

#include <stddef.h>

struct psd_daemon;
struct psd_ctl_reply;
struct psd_cmdtab_args;

/* The reply of a failed request: {"ok":false,"error":...}. */
void psd_ctlcmd_error(struct psd_ctl_reply *reply, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The reply of a request done: {"ok":true}, with key's text when key. */
void psd_ctlcmd_ok(struct psd_ctl_reply *reply, const char *key, const char *text);

/* The commands' handlers, the table's rows' (cmdtab.c): each answers
 * arguments the table's parser has judged (psd_cmdtab_fn). */
void psd_ctlcmd_ping(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_status(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_target(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_off(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_ratios(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_log(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_reload(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_calibrate(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_accept_test(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_dali(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);

#endif
