/* status_t and event_t as JSON objects: what `cnc-ctl status --json` and
 * `events --json` print, and what a browser panel can take as it is. Written
 * into the caller's buffer. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "ncpar/can.h"
#include "ncpar/msg.h"

struct out {
    char *buf;
    size_t size, len;
    int full; /* something did not fit */
};

__attribute__((format(printf, 2, 3))) static void put(struct out *o, const char *fmt, ...)
{
    if (o->full)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf + o->len, o->size - o->len, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= o->size - o->len)
        o->full = 1;
    else
        o->len += (size_t)n;
}

/* A fixed-size text field (NUL-terminated, or not if the sender broke it);
 * "" is null. */
static void put_text(struct out *o, const uint8_t *s, size_t size)
{
    size_t n = strnlen((const char *)s, size);
    if (n == 0) {
        put(o, "null");
        return;
    }
    put(o, "\"");
    for (size_t i = 0; i < n; i++) {
        unsigned c = s[i];
        if (c == '"' || c == '\\')
            put(o, "\\%c", (char)c);
        else if (c < 0x20 || c == 0x7f)
            put(o, "\\u%04x", c);
        else
            put(o, "%c", (char)c);
    }
    put(o, "\"");
}

/* JSON has no NaN or infinity. */
static void put_num(struct out *o, const char *fmt, double v)
{
    if (isfinite(v))
        put(o, fmt, v);
    else
        put(o, "null");
}

static int n_axes(const ncp_status_t *s)
{
    int n = (int)s->n_axes;
    return n < 0 ? 0 : n > 9 ? 9 : n;
}

/* {"x": ..., "y": ...} over the status's axes; bools when b is set. */
static void put_axes(struct out *o, const ncp_status_t *s, const double *v, const int8_t *b)
{
    put(o, "{");
    int first = 1;
    for (int i = 0; i < n_axes(s); i++) {
        if (!isalpha(s->axes[i]))
            continue;
        put(o, "%s\"%c\": ", first ? "" : ", ", tolower(s->axes[i]));
        first = 0;
        if (b)
            put(o, "%s", b[i] ? "true" : "false");
        else
            put_num(o, "%.6f", v[i]);
    }
    put(o, "}");
}

static const char *g5x_name(int index)
{
    static const char *const names[] = {"G54",   "G55",   "G56",  "G57", "G58",
                                        "G59",   "G59.1", "G59.2", "G59.3"};
    return index >= 1 && index <= 9 ? names[index - 1] : NULL;
}

/* ["G1", "G17", ...]: the codes in force (scale: to code*10). */
static void put_codes(struct out *o, char letter, const int16_t *codes, int n, int scale)
{
    put(o, "[");
    for (int i = 0, first = 1; i < n; i++) {
        char name[16];
        if (ncp_msg_code_name(letter, codes[i] * scale, name, sizeof name) < 0)
            continue;
        put(o, "%s\"%s\"", first ? "" : ", ", name);
        first = 0;
    }
    put(o, "]");
}

int ncp_msg_status_json(const ncp_status_t *s, char *buf, size_t size)
{
    struct out o = {.buf = buf, .size = size};
    if (size == 0)
        return -1;
    const char *state = ncp_msg_state_name(s->state);
    put(&o, "{\"state\": ");
    put(&o, state ? "\"%s\"" : "null", state ? state : "");
    put(&o, ", \"program\": ");
    put_text(&o, s->program, sizeof s->program);
    put(&o, ", \"line\": %d, \"homed\": ", (int)s->line);
    put_axes(&o, s, NULL, s->homed);
    put(&o, ", \"pos_cmd\": ");
    put_axes(&o, s, s->pos_cmd, NULL);
    put(&o, ", \"pos_act\": ");
    put_axes(&o, s, s->pos_act, NULL);
    put(&o, ", \"vel\": ");
    put_num(&o, "%.3f", s->vel);
    put(&o, ", \"feed_override\": ");
    put_num(&o, "%.6g", s->feed_override);
    put(&o, ", \"rapid_override\": ");
    put_num(&o, "%.6g", s->rapid_override);
    put(&o, ", \"spindle_override\": ");
    put_num(&o, "%.6g", s->spindle_override);
    put(&o, ", \"spindle\": {\"speed\": ");
    put_num(&o, "%.3f", s->spindle_speed);
    put(&o, ", \"dir\": %d}", (int)s->spindle_dir);
    put(&o, ", \"coolant\": {\"mist\": %s, \"flood\": %s}", s->mist ? "true" : "false",
        s->flood ? "true" : "false");
    put(&o, ", \"tool\": %d", (int)s->tool);
    const char *g5x = g5x_name(s->g5x_index);
    put(&o, ", \"g5x\": {\"index\": %d, \"name\": ", (int)s->g5x_index);
    put(&o, g5x ? "\"%s\"" : "null", g5x ? g5x : "");
    put(&o, ", \"offset\": ");
    put_axes(&o, s, s->g5x_offset, NULL);
    put(&o, "}, \"gcodes\": ");
    put_codes(&o, 'G', s->gcodes, 13, 1);
    put(&o, ", \"mcodes\": ");
    put_codes(&o, 'M', s->mcodes, 4, 10);
    put(&o, ", \"g64\": {\"p\": ");
    put_num(&o, "%.6g", s->g64_p);
    put(&o, ", \"q\": ");
    put_num(&o, "%.6g", s->g64_q);
    put(&o, "}, \"step\": %s, \"error\": ", s->step_mode ? "true" : "false");
    put_text(&o, s->error, sizeof s->error);
    put(&o,
        ", \"seq\": %lld, \"commands\": %lld, \"garbage\": %lld, \"auth_failed\": %lld, "
        "\"stale\": %lld, \"replayed\": %lld, \"rejected\": %lld, "
        "\"cycles\": %lld, \"deadline_misses\": %lld, \"latency_max_us\": ",
        (long long)s->seq, (long long)s->commands, (long long)s->garbage,
        (long long)s->auth_failed, (long long)s->stale, (long long)s->replayed,
        (long long)s->rejected, (long long)s->cycles, (long long)s->deadline_misses);
    put_num(&o, "%.3f", s->latency_max_us);
    const char *est = ncp_msg_estimate_name(s->estimate_state);
    put(&o, ", \"estimate\": {\"state\": ");
    put(&o, est ? "\"%s\"" : "null", est ? est : "");
    put(&o, ", \"program_time_s\": ");
    put_num(&o, "%.6f", s->estimate_s);
    put(&o, ", \"path_length_mm\": ");
    put_num(&o, "%.6f", s->estimate_path_mm);
    put(&o, ", \"max_following_error_mm\": ");
    put_num(&o, "%.6f", s->estimate_ferr_mm);
    put(&o, ", \"compute_s\": ");
    put_num(&o, "%.3f", s->estimate_compute_s);
    put(&o, ", \"pauses\": %d, \"extents\": ", (int)s->estimate_pauses);
    if (s->estimate_min[0] > s->estimate_max[0]) {
        put(&o, "null");
    } else {
        for (int side = 0; side < 2; side++) {
            const float *v = side ? s->estimate_max : s->estimate_min;
            put(&o, side ? "], \"max\": [" : "{\"min\": [");
            for (int j = 0; j < 9; j++) {
                put(&o, j ? ", " : "");
                put_num(&o, "%.4f", (double)v[j]);
            }
        }
        put(&o, "]}");
    }
    put(&o, "}, \"program_time_s\": ");
    put_num(&o, "%.6f", s->program_time_s);
    put(&o, ", \"remaining_s\": ");
    if (s->remaining_s < 0)
        put(&o, "null");
    else
        put_num(&o, "%.3f", s->remaining_s);
    put(&o, ", \"drives\": [");
    for (int k = 0; k < s->n_drives && k < 9; k++) {
        uint16_t sw = (uint16_t)s->drive_statusword[k], err = (uint16_t)s->drive_error[k];
        char axis = isalpha(s->drive_axis[k]) ? (char)s->drive_axis[k] : '?';
        put(&o, "%s{\"axis\": \"%c\", \"node\": %d, \"state\": \"%s\", \"statusword\": "
            "\"0x%04X\", \"error\": \"0x%04X\", \"error_text\": \"%s\"}",
            k ? ", " : "", axis, (int)s->drive_node[k],
            ncp_cia402_state_name(ncp_cia402_state(sw)), sw, err, err ? ncp_emcy_code_text(err) : "");
    }
    put(&o, "], \"llc_dp\": %d, \"llcs\": [", (int)s->llc_dp);
    for (int k = 0; k < s->n_llcs && k < 9; k++) {
        const char *st = ncp_msg_llc_state_name(s->llc_state[k]);
        char axis = isalpha(s->llc_axis[k]) ? (char)s->llc_axis[k] : '?';
        put(&o, "%s{\"axis\": \"%c\", \"state\": ", k ? ", " : "", axis);
        put(&o, st ? "\"%s\"" : "null", st ? st : "");
        const char *err = ncp_msg_llc_error_name(s->llc_error[k]);
        put(&o, ", \"clock_offset_us\": %d, \"ferr_nm\": %d, \"error\": ",
            (int)s->llc_clock_offset_us[k], (int)s->llc_ferr_nm[k]);
        if (err)
            put(&o, "\"%s\"}", err);
        else
            put(&o, "\"error %d\"}", (int)s->llc_error[k]);
    }
    put(&o, "]}");
    return o.full ? -1 : (int)o.len;
}

int ncp_msg_event_json(const ncp_event_t *e, char *buf, size_t size)
{
    struct out o = {.buf = buf, .size = size};
    if (size == 0)
        return -1;
    const char *kind = ncp_msg_event_kind_name(e->kind);
    put(&o, "{\"kind\": ");
    put(&o, kind ? "\"%s\"" : "null", kind ? kind : "");
    put(&o, ", \"channel\": %d, \"seq\": %lld, \"utime\": %lld, \"file\": ", (int)e->channel,
        (long long)e->seq, (long long)e->utime);
    put_text(&o, e->file, sizeof e->file);
    put(&o, ", \"line\": %d, \"col\": %d, \"text\": ", (int)e->line, (int)e->col);
    put_text(&o, e->text, sizeof e->text);
    put(&o, "}");
    return o.full ? -1 : (int)o.len;
}
