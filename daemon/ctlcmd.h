/* SPDX-License-Identifier: ISC */
/* The control socket's commands (daemon/ctlcmd.c): one request line judged
 * by the command table (cmdtab.h) and answered as one JSON line, for the
 * socket, the web console and MQTT alike. */
#ifndef PSD_CTLCMD_H
#define PSD_CTLCMD_H

#include <stddef.h>

struct psd_daemon;
struct psd_ctl_client;
struct psd_ctl_reply;
struct psd_cmdtab_args;

/* 1 when word is the first word of a request psensd answers, else 0: a
 * client refuses a misspelt command before asking. */
int psd_ctlcmd_is_request(const char *word);
/* The control socket's handler (daemon/ctlcmd.c). */
void psd_ctlcmd_handle(void *daemon, const struct psd_ctl_client *c, char *line, struct psd_ctl_reply *reply);
/* One request line, judged and answered (a JSON line in reply, grown as it needs up to
 * PSD_CTL_MAX_REPLY; the caller frees it with psd_ctlsock_reply_free): what the
 * socket's handler and MQTT's set/ topics (daemon/mqtt/mqtt.c) both call. */
void psd_ctlcmd_request(struct psd_daemon *d, char *line, struct psd_ctl_reply *reply);

/* The commands' handlers, the table's rows' (cmdtab.c): each answers
 * arguments the table's parser has judged (psd_cmdtab_fn). */
void psd_ctlcmd_ping(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_help(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_status(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_target(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_override(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_off(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_release(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_ratios(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_log(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_reload(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_calibrate(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_accept_test(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
void psd_ctlcmd_dali(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);

#endif
