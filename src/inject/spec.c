/* The injection specs and their INI keys. The names are fixed: users and
 * tests script against them, so a spec that is not exactly one of them is an
 * error naming it, never a silent no-op. */
#include "ncpar/inject.h"
#include "ncpar/num.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* delay-feedback is served from the plant's recent periods (backend sim) */
#define DELAY_FB_PERIODS NCP_INJECT_FB_HISTORY

void ncp_inject_cfg_default(struct ncp_inject_cfg *c)
{
    memset(c, 0, sizeof *c);
    c->policy = NCP_MISS_HOLD;
    c->window = 1000;
    c->seed = 1;
}

const char *ncp_miss_policy_name(int policy)
{
    static const char *const names[] = { "hold", "extrapolate", "extrapolate2", "timestamped" };
    return policy >= 0 && policy < 4 ? names[policy] : "?";
}

/* A plain decimal and nothing else: no hex, no nan, no unit glued on. */
static int number(const char *s, size_t n, double lo, double hi, double *out)
{
    char buf[64];
    if (n == 0 || n >= sizeof buf || strspn(s, "0123456789.eE+-") < n)
        return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    return ncp_num_double(buf, lo, hi, out);
}

static int bad(char *why, size_t len, const char *spec, size_t n, const char *want)
{
    snprintf(why, len, "bad spec '%.*s': %s", (int)(n > 60 ? 60 : n), spec, want);
    return -1;
}

#define AXIS_NAMES "XYZABCUVW"   /* bit i of an axis mask is AXIS_NAMES[i] */

#define US_MAX 1e6   /* one second: more is no timing fault but a stopped loop */

static int one(struct ncp_inject_cfg *c, const char *s, size_t n, char *why, size_t len)
{
    const char *eq = memchr(s, '=', n), *at = memchr(s, '@', n);
    const char *sep = eq ? eq : at;
    if (!sep)
        return bad(why, len, s, n, "NAME=VALUE or miss@CYCLE");
    size_t kl = (size_t)(sep - s);
    const char *v = sep + 1;
    size_t vl = n - kl - 1;
    double x, y;
#define IS(name) (kl == strlen(name) && !strncmp(s, name, kl))
    if (at && !eq) {
        /* miss@CYCLE:AXES: that cycle's setpoint misses on those axes only */
        const char *colon = memchr(v, ':', vl);
        size_t cl = colon ? (size_t)(colon - v) : vl;
        uint32_t axes = 0;
        for (size_t i = cl + 1; colon && i < vl; i++) {
            const char *l = strchr(AXIS_NAMES, v[i] >= 'a' && v[i] <= 'z' ? v[i] - 32 : v[i]);
            if (!v[i] || !l)
                return bad(why, len, s, n, "miss@CYCLE:AXES wants axis letters, e.g. miss@375:Y");
            axes |= 1u << (l - AXIS_NAMES);
        }
        if (!IS("miss") || number(v, cl, 0, 1e15, &x) || x != floor(x) || (colon && !axes))
            return bad(why, len, s, n,
                       "miss@CYCLE or miss@CYCLE:AXES wants a whole cycle number (0 is the "
                       "first) and axis letters");
        if (c->n_miss_at >= NCP_INJECT_AT_MAX)
            return bad(why, len, s, n, "at most 64 miss@CYCLE specs");
        c->miss_at_axes[c->n_miss_at] = axes;
        c->miss_at[c->n_miss_at++] = (uint64_t)x;
        c->kinds |= NCP_INJ_MISS;
        return 0;
    }
    struct { const char *name; double *dst; unsigned kind; } ratios[] = {
        { "miss", &c->miss_ratio, NCP_INJ_MISS },
        { "lose-setpoint", &c->lose_sp_ratio, NCP_INJ_LOSE_SP },
        { "lose-feedback", &c->lose_fb_ratio, NCP_INJ_LOSE_FB },
    };
    for (size_t i = 0; i < sizeof ratios / sizeof ratios[0]; i++) {
        if (!IS(ratios[i].name))
            continue;
        if (number(v, vl, 0, 1, &x))
            return bad(why, len, s, n, "a ratio from 0 to 1 (0.002 = 0.2 % of the periods)");
        *ratios[i].dst = x;
        c->kinds |= ratios[i].kind;
        return 0;
    }
    if (IS("latency")) {
        const char *dash = vl > 1 ? memchr(v + 1, '-', vl - 1) : NULL;
        if (dash) {
            size_t al = (size_t)(dash - v);
            if (number(v, al, 0, US_MAX, &x) || number(dash + 1, vl - al - 1, 0, US_MAX, &y) ||
                y < x)
                return bad(why, len, s, n, "latency=MIN-MAX in microseconds, MIN <= MAX");
        } else if (number(v, vl, 0, US_MAX, &x)) {
            return bad(why, len, s, n, "latency=US or latency=MIN-MAX in microseconds");
        } else {
            y = x;
        }
        c->lat_min_s = x * 1e-6;
        c->lat_max_s = y * 1e-6;
        c->kinds |= NCP_INJ_LATENCY;
        return 0;
    }
    if (IS("jitter")) {
        const char *colon = memchr(v, ':', vl);
        size_t nl = colon ? (size_t)(colon - v) : vl;
        if (number(v, nl, 0, US_MAX, &x) ||
            (colon && (vl - nl - 1 != 6 || strncmp(colon + 1, "normal", 6) != 0)))
            return bad(why, len, s, n, "jitter=US (uniform) or jitter=US:normal, in microseconds");
        c->jitter_s = x * 1e-6;
        c->jitter_normal = colon != NULL;
        c->kinds |= NCP_INJ_JITTER;
        return 0;
    }
    struct { const char *name; double *dst; unsigned kind; } delays[] = {
        { "io-latency", &c->io_s, NCP_INJ_IO },
        { "delay-feedback", &c->delay_fb_s, NCP_INJ_DELAY_FB },
    };
    for (size_t i = 0; i < sizeof delays / sizeof delays[0]; i++) {
        if (!IS(delays[i].name))
            continue;
        if (number(v, vl, 0, US_MAX, &x))
            return bad(why, len, s, n, "a delay in microseconds");
        *delays[i].dst = x * 1e-6;
        c->kinds |= delays[i].kind;
        return 0;
    }
#undef IS
    return bad(why, len, s, n,
               "unknown; the specs are miss=RATIO, miss@CYCLE, latency=US, latency=MIN-MAX, "
               "io-latency=US, jitter=US[:normal], lose-setpoint=RATIO, lose-feedback=RATIO, "
               "delay-feedback=US");
}

int ncp_inject_parse(struct ncp_inject_cfg *c, const char *list, char *why, size_t len)
{
    const char *p = list;
    if (!*p)
        return snprintf(why, len, "no spec given"), -1;
    for (;;) {
        size_t n = strcspn(p, ",");
        /* blanks around a spec are the writer's layout, not part of it */
        const char *s = p;
        size_t m = n;
        while (m && (*s == ' ' || *s == '\t'))
            s++, m--;
        while (m && (s[m - 1] == ' ' || s[m - 1] == '\t'))
            m--;
        if (one(c, s, m, why, len))
            return -1;
        if (!p[n])
            return 0;
        p += n + 1;
    }
}

static int whole_key(const char *v, double lo, double hi, double *out)
{
    return number(v, strlen(v), lo, hi, out) || *out != floor(*out) ? -1 : 0;
}

int ncp_inject_ini_key(struct ncp_inject_cfg *c, const char *sec, const char *k, const char *v,
                       char *why, size_t len)
{
    double x;
    if (!strcasecmp(sec, "INJECT")) {
        if (!strcasecmp(k, "SPEC"))
            return ncp_inject_parse(c, v, why, len) ? -1 : 1;
        if (!strcasecmp(k, "SEED")) {
            if (whole_key(v, 0, 9007199254740992.0, &x))
                return snprintf(why, len, "a whole number 0 to 2^53"), -1;
            c->seed = (uint64_t)x;
            return 1;
        }
        return 0;
    }
    if (strcasecmp(sec, "RT") != 0)
        return 0;
    if (!strcasecmp(k, "MISS_POLICY")) {
        for (int p = NCP_MISS_HOLD; p <= NCP_MISS_TIMESTAMPED; p++)
            if (!strcasecmp(v, ncp_miss_policy_name(p))) {
                c->policy = p;
                return 1;
            }
        return snprintf(why, len, "hold, extrapolate, extrapolate2 or timestamped"), -1;
    }
    if (!strcasecmp(k, "SETPOINT_FRAMES")) {
        if (strcasecmp(v, "shared") != 0 && strcasecmp(v, "per-axis") != 0)
            return snprintf(why, len, "shared (one frame for every axis) or per-axis"), -1;
        c->per_axis = !strcasecmp(v, "per-axis");
        return 1;
    }
    if (!strcasecmp(k, "MAX_CONSECUTIVE_MISSES")) {
        if (whole_key(v, 0, 1000000, &x))
            return snprintf(why, len, "0 (no limit) to 1000000 periods"), -1;
        c->max_consecutive = (int)x;
        return 1;
    }
    if (!strcasecmp(k, "MAX_MISS_RATIO")) {
        if (number(v, strlen(v), 0, 1, &x))
            return snprintf(why, len, "0 (no limit) to 1, misses per period over MISS_WINDOW"), -1;
        c->max_ratio = x;
        return 1;
    }
    if (!strcasecmp(k, "MISS_WINDOW")) {
        if (whole_key(v, 1, NCP_INJECT_WINDOW_MAX, &x))
            return snprintf(why, len, "1 to %d periods", NCP_INJECT_WINDOW_MAX), -1;
        c->window = (int)x;
        return 1;
    }
    return 0;
}

int ncp_inject_check(const struct ncp_inject_cfg *c, double period_s, char *why, size_t len)
{
    if (c->delay_fb_s > (DELAY_FB_PERIODS - 2) * period_s)
        return snprintf(why, len,
                        "delay-feedback=%.0f is longer than %d servo periods (%.0f us)",
                        c->delay_fb_s * 1e6, DELAY_FB_PERIODS - 2,
                        (DELAY_FB_PERIODS - 2) * period_s * 1e6), -1;
    for (int i = 0; i < c->n_miss_at && !c->per_axis; i++)
        if (c->miss_at_axes[i])
            return snprintf(why, len,
                            "miss@%llu names axes, but one frame carries every axis' setpoint: "
                            "set [RT] SETPOINT_FRAMES = per-axis",
                            (unsigned long long)c->miss_at[i]), -1;
    return 0;
}
