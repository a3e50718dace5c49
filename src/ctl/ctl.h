/* cnc-ctl's side of the conversation with a serving NCK, over liblcm: send a
 * command and wait for its ACK (resending it until answered), wait for
 * STATUS. Exit statuses are the program's. */
#ifndef NCPAR_CTL_H
#define NCPAR_CTL_H

#include <signal.h>
#include <stdint.h>

#include <lcm/lcm.h>

#include "ncpar/msg.h"

enum ctl_exit {
    CTL_OK = 0,        /* accepted; for wait: reached */
    CTL_USAGE = 1,     /* bad command line, or LCM could not be set up */
    CTL_REJECTED = 2,  /* the NCK said no (reason on stderr) */
    CTL_FAULT = 3,     /* the NCK is in fault */
    CTL_NO_ANSWER = 4, /* nothing within the timeout */
};

struct ncp_auth;
struct ctl {
    lcm_t *lcm;
    struct ncp_auth *auth;   /* the NCK's key: seals commands, checks ACKs and status */
    uint64_t unsealed;       /* ACKs and statuses ignored: not sealed with the key */
    const char *url; /* as given, for messages; NULL: liblcm's default */
    char ch_cmd[NCP_MSG_PREFIX_MAX + 8];
    char ch_ack[NCP_MSG_PREFIX_MAX + 8];
    char ch_status[NCP_MSG_PREFIX_MAX + 8];
    char ch_event[NCP_MSG_PREFIX_MAX + 8];
    int8_t channel;  /* NC channel */
    double timeout;  /* seconds; 0: none (wait and status --watch only) */
    int32_t client_id;
    int32_t seq;     /* the last one used */
    /* filled by the handlers */
    int32_t want_seq;
    int have_ack;
    ncp_ack_t ack;
    uint64_t n_status; /* statuses of our NC channel received so far */
    ncp_status_t status;
    double status_at;  /* ctl_now() of the last one */
    /* Statuses of other NC channels while none of ours came: enough of them,
     * over long enough, say that ours is not served (no 5 s wait for it). */
    uint32_t other_statuses;
    double first_other_at;
    uint8_t served[128];   /* NC channels seen in statuses */
    /* events: the follower's printer */
    void (*on_event)(const ncp_event_t *e, void *ctx);
    void *event_ctx;
};

/* Set by SIGINT/SIGTERM (a second one ends the program). */
extern volatile sig_atomic_t ctl_interrupted;
void ctl_catch_signals(void);

double ctl_now(void);
/* key_file NULL: $XDG_CONFIG_HOME/ncpar/lcm.key or ~/.config/ncpar/lcm.key */
int ctl_open(struct ctl *c, const char *url, const char *prefix, const char *key_file);
void ctl_close(struct ctl *c);

/* A command with its fields of the kind filled in: sent with our client id
 * and the next seq. ctl_send only sends; ctl_command sends, resends every
 * 500 ms and waits for the ACK: CTL_OK, CTL_REJECTED, CTL_FAULT or
 * CTL_NO_ANSWER, with the reason printed. */
int ctl_send(struct ctl *c, ncp_command_t *cmd);
int ctl_command(struct ctl *c, ncp_command_t *cmd);
/* After an accepted command (c->ack): waits for a status sent after its ACK
 * whose state is no longer busy_state (jogging for a jog, mdi for an MDI
 * line): CTL_OK, CTL_FAULT when it ended in fault or estop (said on stderr),
 * CTL_NO_ANSWER when no status came for --timeout seconds (the NCK is gone)
 * or interrupted. what names the command in messages. */
int ctl_wait_done(struct ctl *c, int busy_state, const char *what);
/* Handles what arrives for up to seconds: 0, or -1 when LCM failed. */
int ctl_handle(struct ctl *c, double seconds);
/* Waits for the next status (c->status), up to timeout seconds (0: for
 * ever): CTL_OK, CTL_NO_ANSWER, CTL_USAGE when LCM failed (said on stderr),
 * CTL_REJECTED when the NCK's statuses show it serves no such NC channel
 * (said on stderr), -1 when interrupted. */
int ctl_next_status(struct ctl *c, double timeout);
/* "cnc-ctl: no WHAT from the NCK within S s (is ... running?)" */
void ctl_no_answer(const char *what, double seconds);
/* history.c: the last `last` jobs of the NCK's job history (the NCK
 * names the file; read on this host), as text or JSON lines. */
int ctl_history(struct ctl *c, int json, long last);
/* The path of the NCK's "history" or "tool_table" file (its FILES
 * command): CTL_OK with path, or the command's refusal (said). */
int ctl_file_path(struct ctl *c, const char *which, char *path, size_t len);
/* tools.c: the tool table the NCK writes back, read on this host (lengths
 * in mm); a change of tool words[0] by MDI G10 L1 from LETTER VALUE pairs,
 * waited for. */
int ctl_tool_list(struct ctl *c, int json);
int ctl_tool_set(struct ctl *c, const char *const *words, int n);

/* jog AXIS +|-: incremental (distance > 0) or continuous (see cnc-ctl jog
 * --help); speed 0 is the NCK's default. wait: an incremental jog returns
 * when the move has ended, not when it is accepted. */
int ctl_jog(struct ctl *c, char axis, int dir, double speed, double distance, int wait);

/* Calls show for every event of our NC channel that carries the key's seal,
 * for up to seconds (0: until interrupted): CTL_OK, or CTL_USAGE when LCM
 * failed. */
int ctl_follow_events(struct ctl *c, double seconds,
                      void (*show)(const ncp_event_t *e, void *ctx), void *ctx);

/* touch-off AXIS VALUE: G10 L20 in coordinate system `system` (1 = G54 ...
 * 9 = G59.3, 0 the active one); touch-off-tool AXIS VALUE: G10 L10 for the
 * tool in the spindle, then G43. Both wait until the NCK has run them. */
int ctl_touch_off(struct ctl *c, char axis, double value, int system);
int ctl_touch_off_tool(struct ctl *c, char axis, double value);

/* cnc-ctl events: one line, "FILE:LINE:COL: error: TEXT" the way a compiler
 * says it where the event names a place. */
void ctl_print_event(const ncp_event_t *e);

/* cnc-ctl status: the readable lines. */
void ctl_print_status(const ncp_status_t *s);

#endif
