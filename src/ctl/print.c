/* cnc-ctl status and events without --json: what a machinist reads at a
 * glance. */
#include <stdio.h>
#include <string.h>

#include "ctl.h"
#include "ncpar/can.h"

static int n_axes(const ncp_status_t *s)
{
    return s->n_axes < 0 ? 0 : s->n_axes > 9 ? 9 : s->n_axes;
}

static void print_axes(const char *label, const ncp_status_t *s, const double *v)
{
    printf("%-9s", label);
    for (int i = 0; i < n_axes(s); i++)
        printf(" %c %11.4f", s->axes[i], v[i]);
    printf("\n");
}

static const char *text_of(const uint8_t *t, size_t size, char *buf, size_t bufsize)
{
    snprintf(buf, bufsize, "%.*s", (int)strnlen((const char *)t, size), (const char *)t);
    return buf;
}

/* The loaded program's time before it runs (and the last run's beside it,
 * the two a machinist compares). */
static void print_estimate(const ncp_status_t *s)
{
    const char *name = ncp_msg_estimate_name(s->estimate_state);
    if (s->estimate_state == NCP_STATUS_T_EST_DONE) {
        printf("estimate  program time %.3f s, path %.3f mm, max following error %.4f mm, "
               "%d pauses\n", s->estimate_s, s->estimate_path_mm, s->estimate_ferr_mm,
               (int)s->estimate_pauses);
        if (s->estimate_min[0] <= s->estimate_max[0]) {
            printf("extents  ");
            for (int i = 0; i < n_axes(s); i++) {
                const char *at = strchr("XYZABCUVW", s->axes[i]);
                if (at && s->axes[i])
                    printf(" %c %.3f..%.3f", s->axes[i], (double)s->estimate_min[at - "XYZABCUVW"],
                           (double)s->estimate_max[at - "XYZABCUVW"]);
            }
            printf("\n");
        }
    } else if (s->estimate_state != NCP_STATUS_T_EST_NONE) {
        printf("estimate  %s\n", name ? name : "unknown");
    }
    if (s->remaining_s >= 0)
        printf("remaining %.1f s at the feed override now\n", s->remaining_s);
    if (s->program_time_s > 0)
        printf("last run  program time %.3f s\n", s->program_time_s);
}

void ctl_print_status(const ncp_status_t *s)
{
    static const char *const g5x[] = {"G54", "G55", "G56", "G57", "G58",
                                      "G59", "G59.1", "G59.2", "G59.3"};
    char buf[260];
    const char *state = ncp_msg_state_name(s->state);
    printf("state     %s%s\n", state ? state : "unknown", s->step_mode ? " (single block)" : "");
    text_of(s->program, sizeof s->program, buf, sizeof buf);
    if (buf[0])
        printf("program   %s, line %d\n", buf, (int)s->line);
    else
        printf("program   none\n");
    print_axes("position", s, s->pos_cmd);
    print_axes("actual", s, s->pos_act);
    printf("homed    ");
    int homed = 0;
    for (int i = 0; i < n_axes(s); i++)
        if (s->homed[i]) {
            printf(" %c", s->axes[i]);
            homed++;
        }
    printf("%s\n", homed == 0 ? " none" : "");
    printf("feed      %.1f mm/min, overrides feed %.0f%% rapid %.0f%% spindle %.0f%%\n",
           s->vel, s->feed_override, s->rapid_override, s->spindle_override);
    printf("spindle   %.0f rpm %s, coolant %s%s%s, tool %d, %s\n", s->spindle_speed,
           s->spindle_dir > 0 ? "cw" : s->spindle_dir < 0 ? "ccw" : "stopped",
           s->mist ? "mist" : "", s->mist && s->flood ? "+" : "",
           s->flood ? "flood" : (s->mist ? "" : "off"), (int)s->tool,
           s->g5x_index >= 1 && s->g5x_index <= 9 ? g5x[s->g5x_index - 1] : "G5x?");
    if (ncp_msg_active_codes_text(s, buf, sizeof buf) > 0)
        printf("modal     %s\n", buf);
    print_estimate(s);
    text_of(s->error, sizeof s->error, buf, sizeof buf);
    if (buf[0])
        printf("error     %s\n", buf);
    printf("messages  %lld commands, %lld garbage, %lld rejected; loop %lld cycles, %lld "
           "misses, %.1f us worst latency\n",
           (long long)s->commands, (long long)s->garbage, (long long)s->rejected,
           (long long)s->cycles, (long long)s->deadline_misses, s->latency_max_us);
    printf("dropped   %lld without the key's seal, %lld past their deadline, %lld replayed\n",
           (long long)s->auth_failed, (long long)s->stale, (long long)s->replayed);
    for (int k = 0; k < s->n_drives && k < 9; k++) {
        uint16_t sw = (uint16_t)s->drive_statusword[k], err = (uint16_t)s->drive_error[k];
        printf("drive %c   node %d: %s, statusword 0x%04X", s->drive_axis[k], (int)s->drive_node[k],
               ncp_cia402_state_name(ncp_cia402_state(sw)), sw);
        if (err)
            printf(", last EMCY 0x%04X %s", err, ncp_emcy_code_text(err));
        printf("\n");
    }
    for (int k = 0; k < s->n_llcs && k < 9; k++) {
        const char *st = ncp_msg_llc_state_name(s->llc_state[k]);
        const char *err = ncp_msg_llc_error_name(s->llc_error[k]);
        printf("llc %c     DP %d: %s, clock offset %d us, following error %d nm",
               s->llc_axis[k], (int)s->llc_dp, st ? st : "?", (int)s->llc_clock_offset_us[k],
               (int)s->llc_ferr_nm[k]);
        /* kept until a reset; its whole text was an event (cnc-ctl events) */
        if (!err || err[0])
            printf(", last error: %s", err ? err : "?");
        printf("\n");
    }
}

void ctl_print_event(const ncp_event_t *e)
{
    char file[260], text[520];
    const char *kind = ncp_msg_event_kind_name(e->kind);
    kind = kind ? kind : "event";
    text_of(e->text, sizeof e->text, text, sizeof text);
    if (e->file[0] && e->line > 0)
        printf("%s:%d:%d: %s: %s\n", text_of(e->file, sizeof e->file, file, sizeof file),
               (int)e->line, (int)e->col, kind, text);
    else if (e->file[0])
        printf("%s: %s: %s\n", text_of(e->file, sizeof e->file, file, sizeof file), kind, text);
    else if (e->line > 0)
        printf("line %d: %s: %s\n", (int)e->line, kind, text);
    else
        printf("%s: %s\n", kind, text);
}
