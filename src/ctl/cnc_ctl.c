/* cnc-ctl: the operator's command-line client of a serving NCK (`cnc-run
 * serve`), one command per call, over LCM.
 *   cnc-ctl [--lcm-url URL] [--prefix P] [--timeout S] [--channel N] COMMAND ...
 * Exit status: 0 accepted (wait: reached), 1 usage, 2 rejected, 3 the NCK is in
 * fault, 4 no answer within the timeout. */
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "ctl.h"
#include "ncp_version.h"
#include "ncpar/num.h"

#define MAX_WORDS 64

enum {
    OPT_JSON = 1 << 0,
    OPT_WATCH = 1 << 1,
    OPT_FROM_LINE = 1 << 2,
    OPT_SPEED = 1 << 3,
    OPT_DISTANCE = 1 << 4,
    OPT_WAIT = 1 << 5,
    OPT_SYSTEM = 1 << 6,
    OPT_COUNT = 1 << 7,
};

struct args {
    const char *url, *prefix, *key_file;
    double timeout;
    int timeout_given;
    long channel;
    unsigned opts; /* OPT_* given */
    long from_line;
    long count;     /* -n N */
    double speed, distance;
    int system; /* --system: 1 = G54 ... 9 = G59.3 */
    int help;
    const char *name; /* the command */
    const char *words[MAX_WORDS];
    int n_words;
};

struct command {
    const char *name;
    const char *usage; /* after the name */
    const char *help;
    unsigned opts;     /* OPT_* allowed */
    int min_words, max_words;
    int (*run)(struct ctl *c, const struct args *a);
};

static const struct command *find_command(const char *name);

static const char global_usage[] =
    "usage: cnc-ctl [--lcm-url URL] [--prefix P] [--key-file F] [--timeout S] [--channel N]\n"
    "               COMMAND ...\n"
    "\n"
    "The operator's client of a serving NCK (cnc-run serve), one command per call.\n"
    "\n"
    "  --lcm-url URL   LCM URL (default: $LCM_DEFAULT_URL, else\n"
    "                  udpm://239.255.76.67:7667?ttl=0)\n"
    "  --prefix P      channel prefix of the NCK (default NCP_)\n"
    "  --key-file F    the NCK's key (default: $XDG_CONFIG_HOME/ncpar/lcm.key, else\n"
    "                  ~/.config/ncpar/lcm.key): commands are sealed with it, and\n"
    "                  ACKs and statuses without its seal are ignored\n"
    "  --timeout S     seconds to wait for an answer (default 5; for wait and\n"
    "                  status --watch 0 waits for ever; events follow until ^C\n"
    "                  unless it is given). A command the NCK has not\n"
    "                  taken by then is never acted on (its deadline travels with it)\n"
    "  --channel N     NC channel (default 0)\n"
    "\n"
    "commands (cnc-ctl COMMAND --help for each):\n"
    "  status [--json] [--watch]          events [--json]\n"
    "  history [--json] [-n N]            tool list [--json] | tool set T Z MM D MM ...\n"
    "  load PROG          run [--from-line N]                 mdi 'LINE'\n"
    "  pause   resume   stop   abort      step on|off\n"
    "  home [AXES|all]                    override feed|rapid|spindle PCT\n"
    "  jog AXIS +|- [--speed MM_PER_MIN] [--distance MM [--wait]]   jog AXIS stop\n"
    "  touch-off AXIS VALUE [--system G54..G59.3]   touch-off-tool AXIS VALUE\n"
    "  estop   reset   shutdown           wait STATE [--timeout S]\n"
    "  tool-changed   optional-stop on|off   set-input N 0|1\n"
    "\n"
    "Exit status: 0 accepted (wait: reached), 1 usage, 2 rejected (the reason on\n"
    "stderr), 3 the NCK is in fault, 4 no answer within the timeout.\n";

static int usage_error(const char *fmt, const char *arg)
{
    fputs("cnc-ctl: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs(" (cnc-ctl --help)\n", stderr);
    return CTL_USAGE;
}

/* --name VALUE or --name=VALUE: the value, or NULL (and *i moved on). */
static const char *opt_value(int argc, char **argv, int *i, const char *name)
{
    size_t n = strlen(name);
    const char *a = argv[*i];
    if (strncmp(a, name, n) != 0)
        return NULL;
    if (a[n] == '=')
        return a + n + 1;
    if (a[n] == 0 && *i + 1 < argc)
        return argv[++*i];
    return NULL;
}

static int is_opt(const char *a, const char *name)
{
    size_t n = strlen(name);
    return strncmp(a, name, n) == 0 && (a[n] == 0 || a[n] == '=');
}

/* G54..G59.3 (any case): 1..9, else 0. */
static int coordinate_system(const char *s)
{
    static const char *const names[] = {"G54", "G55", "G56", "G57", "G58",
                                        "G59", "G59.1", "G59.2", "G59.3"};
    for (int i = 0; i < 9; i++)
        if (strcasecmp(s, names[i]) == 0)
            return i + 1;
    return 0;
}

static int parse_args(int argc, char **argv, struct args *a)
{
    memset(a, 0, sizeof *a);
    a->prefix = NCP_MSG_DEFAULT_PREFIX;
    a->timeout = 5.0;
    int only_words = 0;
    for (int i = 1; i < argc; i++) {
        const char *s = argv[i];
        const char *v;
        /* a negative number is a word (touch-off Y -2.5), not an option */
        int number = s[0] == '-' && (isdigit((unsigned char)s[1]) || s[1] == '.');
        if (only_words || s[0] != '-' || strcmp(s, "-") == 0 || number) {
            if (a->name == NULL)
                a->name = s;
            else if (a->n_words < MAX_WORDS)
                a->words[a->n_words++] = s;
            else
                return usage_error("too many arguments%s", "");
            continue;
        }
        if (strcmp(s, "--") == 0) {
            only_words = 1;
        } else if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
            a->help = 1;
        } else if (strcmp(s, "--json") == 0) {
            a->opts |= OPT_JSON;
        } else if (strcmp(s, "--watch") == 0) {
            a->opts |= OPT_WATCH;
        } else if (strcmp(s, "--wait") == 0) {
            a->opts |= OPT_WAIT;
        } else if (is_opt(s, "--system")) {
            v = opt_value(argc, argv, &i, "--system");
            if (v == NULL || (a->system = coordinate_system(v)) == 0)
                return usage_error("--system needs a coordinate system G54 G55 G56 G57 G58 "
                                   "G59 G59.1 G59.2 G59.3, not '%s'", v ? v : "");
            a->opts |= OPT_SYSTEM;
        } else if (is_opt(s, "--lcm-url")) {
            if ((a->url = opt_value(argc, argv, &i, "--lcm-url")) == NULL)
                return usage_error("%s needs a URL", s);
        } else if (is_opt(s, "--key-file")) {
            if ((a->key_file = opt_value(argc, argv, &i, "--key-file")) == NULL)
                return usage_error("%s needs a file", s);
        } else if (is_opt(s, "--prefix")) {
            if ((a->prefix = opt_value(argc, argv, &i, "--prefix")) == NULL)
                return usage_error("%s needs a channel prefix", s);
        } else if (is_opt(s, "--timeout")) {
            v = opt_value(argc, argv, &i, "--timeout");
            if (v == NULL || ncp_num_double(v, 0, DBL_MAX, &a->timeout) != 0)
                return usage_error("--timeout needs seconds (0 or more), not '%s'", v ? v : "");
            a->timeout_given = 1;
        } else if (is_opt(s, "--channel")) {
            v = opt_value(argc, argv, &i, "--channel");
            if (v == NULL || ncp_num_long(v, 10, 0, 127, &a->channel) != 0)
                return usage_error("--channel needs an NC channel 0..127, not '%s'", v ? v : "");
        } else if (is_opt(s, "-n")) {
            v = opt_value(argc, argv, &i, "-n");
            if (v == NULL || ncp_num_long(v, 10, 1, 1000000, &a->count) != 0)
                return usage_error("-n needs a number of jobs (1 or more), not '%s'",
                                   v ? v : "");
            a->opts |= OPT_COUNT;
        } else if (is_opt(s, "--from-line")) {
            v = opt_value(argc, argv, &i, "--from-line");
            if (v == NULL || ncp_num_long(v, 10, 0, INT32_MAX, &a->from_line) != 0)
                return usage_error("--from-line needs a line number, not '%s'", v ? v : "");
            a->opts |= OPT_FROM_LINE;
        } else if (is_opt(s, "--speed")) {
            v = opt_value(argc, argv, &i, "--speed");
            if (v == NULL || ncp_num_double(v, -DBL_MAX, DBL_MAX, &a->speed) != 0 ||
                a->speed <= 0)
                return usage_error("--speed needs mm/min above 0, not '%s'", v ? v : "");
            a->opts |= OPT_SPEED;
        } else if (is_opt(s, "--distance")) {
            v = opt_value(argc, argv, &i, "--distance");
            if (v == NULL || ncp_num_double(v, -DBL_MAX, DBL_MAX, &a->distance) != 0 ||
                a->distance <= 0)
                return usage_error("--distance needs mm above 0, not '%s'", v ? v : "");
            a->opts |= OPT_DISTANCE;
        } else {
            return usage_error("unknown option '%s'", s);
        }
    }
    return CTL_OK;
}

/* ---- commands ------------------------------------------------------------ */

static void init_cmd(ncp_command_t *cmd, int16_t kind)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->kind = kind;
}

static int set_text(ncp_command_t *cmd, const char *text)
{
    size_t n = strlen(text);
    if (n >= sizeof cmd->text)
        return usage_error("'%.40s...' is too long (511 characters at most)", text);
    memcpy(cmd->text, text, n + 1);
    return CTL_OK;
}

/* One axis letter of XYZABCUVW, upper case, or 0. */
static char axis_letter(const char *s)
{
    if (s[0] == 0 || s[1] != 0)
        return 0;
    char up = (char)toupper((unsigned char)s[0]);
    return strchr("XYZABCUVW", up) ? up : 0;
}

static int simple(struct ctl *c, int16_t kind)
{
    ncp_command_t cmd;
    init_cmd(&cmd, kind);
    return ctl_command(c, &cmd);
}

static int run_pause(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_PAUSE);
}
static int run_resume(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_RESUME);
}
static int run_stop(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_STOP);
}
static int run_abort(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_ABORT);
}
static int run_estop(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_ESTOP);
}
static int run_reset(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_RESET);
}
static int run_shutdown(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_SHUTDOWN);
}

static int run_load(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_LOAD);
    /* The NCK may run in another folder: send the path it can open. A path
     * that is not here may still be on the NCK's host if it is absolute. */
    char *path = realpath(a->words[0], NULL);
    if (path == NULL && a->words[0][0] != '/') {
        fprintf(stderr, "cnc-ctl: load: cannot find %s: %s\n", a->words[0], strerror(errno));
        return CTL_USAGE;
    }
    int rc = set_text(&cmd, path ? path : a->words[0]);
    free(path);
    return rc != CTL_OK ? rc : ctl_command(c, &cmd);
}

static int run_run(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_RUN);
    cmd.ivalue[0] = (int32_t)a->from_line;
    return ctl_command(c, &cmd);
}

static int run_tool_changed(struct ctl *c, const struct args *a)
{
    (void)a;
    return simple(c, NCP_COMMAND_T_TOOL_CHANGED);
}

static int run_optional_stop(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_OPTIONAL_STOP);
    if (strcmp(a->words[0], "on") == 0)
        cmd.ivalue[0] = 1;
    else if (strcmp(a->words[0], "off") != 0)
        return usage_error("optional-stop: on or off, not '%s'", a->words[0]);
    return ctl_command(c, &cmd);
}

static int run_set_input(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    long i, v;
    init_cmd(&cmd, NCP_COMMAND_T_SET_INPUT);
    if (ncp_num_long(a->words[0], 10, 0, 63, &i) != 0)
        return usage_error("set-input: a digital input 0..63, not '%s'", a->words[0]);
    if (ncp_num_long(a->words[1], 10, 0, 1, &v) != 0)
        return usage_error("set-input: the value is 0 or 1, not '%s'", a->words[1]);
    cmd.ivalue[0] = (int32_t)i;
    cmd.ivalue[1] = (int32_t)v;
    return ctl_command(c, &cmd);
}

static int run_step(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_STEP);
    if (strcmp(a->words[0], "on") == 0)
        cmd.ivalue[0] = 1;
    else if (strcmp(a->words[0], "off") != 0)
        return usage_error("step: on or off, not '%s'", a->words[0]);
    return ctl_command(c, &cmd);
}

static int run_mdi(struct ctl *c, const struct args *a)
{
    /* words may come unquoted: mdi G0 X10 is mdi 'G0 X10' */
    char line[sizeof ((ncp_command_t *)0)->text];
    size_t len = 0;
    for (int i = 0; i < a->n_words; i++) {
        size_t n = strlen(a->words[i]);
        if (len + n + 1 >= sizeof line)
            return usage_error("mdi: the line is too long (511 characters at most)%s", "");
        if (i > 0)
            line[len++] = ' ';
        memcpy(line + len, a->words[i], n);
        len += n;
    }
    line[len] = 0;
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_MDI);
    int rc = set_text(&cmd, line);
    return rc != CTL_OK ? rc : ctl_command(c, &cmd);
}

static int run_home(struct ctl *c, const struct args *a)
{
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_HOME);
    const char *w = a->n_words ? a->words[0] : "all";
    if (strcmp(w, "all") != 0) {
        size_t k = strlen(w);
        if (k == 0 || k > 9 || strspn(w, "XYZABCUVWxyzabcuvw") != k)
            return usage_error("home: axis letters (XYZABCUVW, e.g. Z or XY) or all, not '%s'",
                               w);
    }
    (void)set_text(&cmd, w);
    return ctl_command(c, &cmd);
}

static int run_override(struct ctl *c, const struct args *a)
{
    static const char *const which[] = {"feed", "rapid", "spindle"};
    ncp_command_t cmd;
    init_cmd(&cmd, NCP_COMMAND_T_OVERRIDE);
    int k = -1;
    for (int i = 0; i < 3; i++)
        if (strcmp(a->words[0], which[i]) == 0)
            k = i;
    if (k < 0)
        return usage_error("override: feed, rapid or spindle, not '%s'", a->words[0]);
    char pct[32];
    snprintf(pct, sizeof pct, "%s", a->words[1]);
    size_t n = strlen(pct);
    if (n > 0 && pct[n - 1] == '%')
        pct[n - 1] = 0;
    if (ncp_num_double(pct, 0, DBL_MAX, &cmd.value[0]) != 0)
        return usage_error("override: a percentage (0 or more), not '%s'", a->words[1]);
    cmd.ivalue[0] = k;
    return ctl_command(c, &cmd);
}

static int run_status(struct ctl *c, const struct args *a)
{
    int json = (a->opts & OPT_JSON) != 0;
    for (;;) {
        int rc = ctl_next_status(c, c->timeout > 0 || !(a->opts & OPT_WATCH) ? c->timeout
                                                                               : 0);
        if (rc < 0)
            return CTL_OK; /* interrupted while watching */
        if (rc == CTL_NO_ANSWER)
            ctl_no_answer("status", c->timeout);
        if (rc != CTL_OK)
            return rc;
        if (json) {
            char buf[8192];
            if (ncp_msg_status_json(&c->status, buf, sizeof buf) > 0)
                printf("%s\n", buf);
        } else {
            ctl_print_status(&c->status);
        }
        fflush(stdout);
        if (!(a->opts & OPT_WATCH))
            return c->status.state == NCP_STATUS_T_FAULT ? CTL_FAULT : CTL_OK;
        if (!json)
            printf("\n");
    }
}

static void show_event(const ncp_event_t *e, void *ctx)
{
    if (*(const int *)ctx) {
        char buf[2048];
        if (ncp_msg_event_json(e, buf, sizeof buf) > 0)
            printf("%s\n", buf);
    } else {
        ctl_print_event(e);
    }
    fflush(stdout);
}

static int run_events(struct ctl *c, const struct args *a)
{
    int json = (a->opts & OPT_JSON) != 0;
    return ctl_follow_events(c, a->timeout_given ? c->timeout : 0, show_event, &json);
}

static int run_tool(struct ctl *c, const struct args *a)
{
    if (!strcmp(a->words[0], "list") && a->n_words == 1)
        return ctl_tool_list(c, (a->opts & OPT_JSON) != 0);
    if (!strcmp(a->words[0], "set") && a->n_words >= 3 && !(a->opts & OPT_JSON))
        return ctl_tool_set(c, a->words + 1, a->n_words - 1);
    return usage_error("tool list [--json] | tool set T LETTER VALUE ...%s", "");
}

static int run_history(struct ctl *c, const struct args *a)
{
    return ctl_history(c, (a->opts & OPT_JSON) != 0, a->opts & OPT_COUNT ? a->count : 20);
}

static int run_wait(struct ctl *c, const struct args *a)
{
    int want = ncp_msg_state_parse(a->words[0]);
    if (want < 0)
        return usage_error("wait: a state (idle running paused stepping mdi jogging homing "
                           "stopping estop fault), not '%s'",
                           a->words[0]);
    double end = ctl_now() + c->timeout;
    for (;;) {
        double left = c->timeout > 0 ? end - ctl_now() : 0;
        if (c->timeout > 0 && left <= 0)
            left = 1e-3;
        uint64_t seen = c->n_status;
        int rc = ctl_next_status(c, left);
        if (rc < 0)
            return CTL_NO_ANSWER; /* interrupted: not reached */
        if (rc == CTL_NO_ANSWER && seen == 0)
            ctl_no_answer("status", c->timeout);
        if (rc == CTL_NO_ANSWER && seen > 0) {
            const char *now = ncp_msg_state_name(c->status.state);
            fprintf(stderr, "cnc-ctl: wait: not %s within %g s (the NCK is %s)\n", a->words[0],
                    c->timeout, now ? now : "in an unknown state");
        }
        if (rc != CTL_OK)
            return rc;
        if (c->status.state == want)
            return CTL_OK;
        if (c->status.state == NCP_STATUS_T_FAULT) {
            fprintf(stderr, "cnc-ctl: wait: the NCK is in fault: %.*s\n",
                    (int)strnlen((const char *)c->status.error, sizeof c->status.error),
                    (const char *)c->status.error);
            return CTL_FAULT;
        }
    }
}

static int run_jog(struct ctl *c, const struct args *a)
{
    char axis = axis_letter(a->words[0]);
    if (!axis)
        return usage_error("jog: an axis letter (XYZABCUVW), not '%s'", a->words[0]);
    const char *d = a->words[1];
    if (strcmp(d, "stop") == 0) {
        if (a->opts & (OPT_SPEED | OPT_DISTANCE))
            return usage_error("jog %s stop takes no --speed or --distance", a->words[0]);
        ncp_command_t cmd;
        init_cmd(&cmd, NCP_COMMAND_T_JOG_STOP);
        cmd.text[0] = (uint8_t)axis;
        return ctl_command(c, &cmd);
    }
    if (strcmp(d, "+") != 0 && strcmp(d, "-") != 0)
        return usage_error("jog: + or - or stop, not '%s'", d);
    if ((a->opts & OPT_WAIT) && !(a->opts & OPT_DISTANCE))
        return usage_error("jog: --wait is for a jog with --distance (a continuous jog "
                           "stays until it ends)%s", "");
    return ctl_jog(c, axis, d[0] == '+' ? 1 : -1, a->opts & OPT_SPEED ? a->speed : 0,
                   a->opts & OPT_DISTANCE ? a->distance : 0, (a->opts & OPT_WAIT) != 0);
}

/* touch-off AXIS VALUE and touch-off-tool AXIS VALUE: the axis and the
 * value the current position is to have. */
static int touch_words(const struct args *a, const char *what, char *axis, double *value)
{
    if (!(*axis = axis_letter(a->words[0])))
        return usage_error("an axis letter (XYZABCUVW), not '%s'", a->words[0]);
    if (ncp_num_double(a->words[1], -DBL_MAX, DBL_MAX, value) != 0)
        return usage_error(what, a->words[1]);
    return CTL_OK;
}

static int run_touch_off(struct ctl *c, const struct args *a)
{
    char axis;
    double v;
    int rc = touch_words(a, "touch-off: the position the axis is to have, in mm (degrees), "
                            "not '%s'", &axis, &v);
    return rc != CTL_OK ? rc : ctl_touch_off(c, axis, v, a->opts & OPT_SYSTEM ? a->system : 0);
}

static int run_touch_off_tool(struct ctl *c, const struct args *a)
{
    char axis;
    double v;
    int rc = touch_words(a, "touch-off-tool: the position the tool tip is to have, in mm, "
                            "not '%s'", &axis, &v);
    return rc != CTL_OK ? rc : ctl_touch_off_tool(c, axis, v);
}

static const struct command commands[] = {
    {"status", "[--json] [--watch]",
     "Waits for the NCK's next status and prints it: a few lines, or with --json one\n"
     "JSON object. --watch prints every status until interrupted (one JSON object a\n"
     "line with --json). Exit 3 when the NCK is in fault, 4 when no status comes.",
     OPT_JSON | OPT_WATCH, 0, 0, run_status},
    {"events", "[--json]",
     "Prints the NCK's events as they come (MSG, DEBUG and PRINT text from the\n"
     "program, its errors as FILE:LINE:COL, faults, the NCK's notices), one a line\n"
     "(one JSON object a line with --json), until interrupted, or for --timeout S\n"
     "seconds when given. Only events from then on: none is kept for later.",
     OPT_JSON, 0, 0, run_events},
    {"tool", "list [--json] | set T [Z MM] [X MM] [D MM] [Q N] ...",
     "list: the NCK's tool table (the file it writes back, read on this host;\n"
     "lengths in mm). set: changes tool T's offsets (X Y Z ... in mm), diameter D\n"
     "(mm), orientation Q, angles I J, as MDI G10 L1 does, waited for; the NCK\n"
     "rewrites the tool table whole. Refused while a program runs, as MDI is.",
     OPT_JSON, 1, MAX_WORDS, run_tool},
    {"history", "[--json] [-n N]",
     "The last N jobs (20 by default) of the NCK's job history, newest last: start,\n"
     "result (done error stopped estop fault), program time and the estimate made\n"
     "at the load, program, reason; with --json the lines as the NCK wrote them\n"
     "(start, end, program, sha256, result, reason, program_time_s,\n"
     "max_following_error_mm, estimate_s). The file\n"
     "is the INI's [DISPLAY] HISTORY_FILE, whose path the NCK gives, read on this host.",
     OPT_JSON | OPT_COUNT, 0, 0, run_history},
    {"load", "PROG", "Loads a program (its path made absolute here).", 0, 1, 1, run_load},
    {"run", "[--from-line N]", "Runs the loaded program, from line N if given.",
     OPT_FROM_LINE, 0, 0, run_run},
    {"pause", "", "Feed hold: the path stops where it is.", 0, 0, 0, run_pause},
    {"resume", "", "Continues after pause (or the next block in step mode).", 0, 0, 0,
     run_resume},
    {"tool-changed", "", "The tool an M6 waits for is in the spindle: the program goes on.",
     0, 0, 0, run_tool_changed},
    {"optional-stop", "on|off", "Whether M1 pauses the program (on by default).", 0, 1, 1,
     run_optional_stop},
    {"set-input", "N 0|1", "Sets digital input N (what M66 P<N> waits on).", 0, 2, 2,
     run_set_input},
    {"stop", "", "Stops the program with a controlled stop.", 0, 0, 0, run_stop},
    {"abort", "", "Abandons the program and motion at once.", 0, 0, 0, run_abort},
    {"step", "on|off", "Single-block mode on or off.", 0, 1, 1, run_step},
    {"mdi", "'LINE'", "Executes one line of G-code.", 0, 1, MAX_WORDS, run_mdi},
    {"home", "[AXES|all]", "Homes the axes named (XZ), or all of them by HOME_SEQUENCE.", 0, 0, 1,
     run_home},
    {"override", "feed|rapid|spindle PCT", "Sets an override, in percent.", 0, 2, 2,
     run_override},
    {"touch-off", "AXIS VALUE [--system G54..G59.3]",
     "Sets the work offset of the coordinate system (the active one when --system\n"
     "is not given) so that the current position of AXIS reads VALUE there: MDI\n"
     "G10 L20, run and waited for. Refused while a program runs, as MDI is.",
     OPT_SYSTEM, 2, 2, run_touch_off},
    {"touch-off-tool", "AXIS VALUE",
     "Sets the offset of the tool in the spindle so that the tool tip's current\n"
     "position on AXIS reads VALUE (MDI G10 L10, then G43 to put it in force), as\n"
     "LinuxCNC's tool touch-off. Refused with no tool in the spindle.",
     0, 2, 2, run_touch_off_tool},
    {"jog", "AXIS +|-|stop [--speed MM_PER_MIN] [--distance MM [--wait]]",
     "With --distance, moves AXIS that far and returns on the answer (with --wait,\n"
     "when the move has ended: the next jog is not refused as one while jogging;\n"
     "exit 3 if it ended in fault or estop). Without it, a\n"
     "continuous jog: cnc-ctl stays in the foreground keeping the jog alive until\n"
     "^C (or SIGTERM), then stops the axis; it also ends when the jog has been\n"
     "stopped otherwise (another client, a soft limit). `jog AXIS stop` stops a jog.",
     OPT_SPEED | OPT_DISTANCE | OPT_WAIT, 2, 2, run_jog},
    {"estop", "", "Emergency stop.", 0, 0, 0, run_estop},
    {"reset", "", "Leaves estop or fault.", 0, 0, 0, run_reset},
    {"shutdown", "", "Ends the NCK service.", 0, 0, 0, run_shutdown},
    {"wait", "STATE [--timeout S]",
     "Watches the status until the NCK's state is STATE (idle running paused\n"
     "stepping mdi jogging homing stopping estop fault): 0; 3 when it is fault\n"
     "instead; 4 after the timeout (--timeout 0: none).",
     0, 1, 1, run_wait},
};

static const struct command *find_command(const char *name)
{
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(commands[i].name, name) == 0)
            return &commands[i];
    return NULL;
}

static void command_help(const struct command *k)
{
    printf("usage: cnc-ctl [OPTIONS] %s%s%s\n\n%s\n", k->name, k->usage[0] ? " " : "",
           k->usage, k->help);
}

int main(int argc, char **argv)
{
    struct args a;
    if (argc == 2 && strcmp(argv[1], "--version") == 0) {
        printf("cnc-ctl (ncpar) %s\n", NCP_VERSION);
        return CTL_OK;
    }
    if (parse_args(argc, argv, &a) != CTL_OK)
        return CTL_USAGE;
    if (a.name && strcmp(a.name, "help") == 0) {
        const struct command *k = a.n_words ? find_command(a.words[0]) : NULL;
        if (k)
            command_help(k);
        else
            fputs(global_usage, stdout);
        return CTL_OK;
    }
    if (a.name == NULL) {
        if (a.help) {
            fputs(global_usage, stdout);
            return CTL_OK;
        }
        fputs(global_usage, stderr);
        return CTL_USAGE;
    }
    const struct command *k = find_command(a.name);
    if (k == NULL)
        return usage_error("unknown command '%s'", a.name);
    if (a.help) {
        command_help(k);
        return CTL_OK;
    }
    if (a.opts & ~k->opts)
        return usage_error("an option that %s does not take", k->name);
    if (a.n_words < k->min_words || a.n_words > k->max_words) {
        fprintf(stderr, "usage: cnc-ctl [OPTIONS] %s %s\n", k->name, k->usage);
        return CTL_USAGE;
    }
    if (a.timeout == 0 && k->run != run_wait && k->run != run_status && k->run != run_events)
        return usage_error("--timeout 0 is only for wait, status --watch and events%s", "");

    struct ctl c;
    memset(&c, 0, sizeof c);
    c.channel = (int8_t)a.channel;
    c.timeout = a.timeout;
    if (k->run == run_status && !(a.opts & OPT_WATCH) && c.timeout == 0)
        c.timeout = 5.0;
    int rc = ctl_open(&c, a.url, a.prefix, a.key_file);
    if (rc == CTL_OK) {
        ctl_catch_signals();
        rc = k->run(&c, &a);
    }
    ctl_close(&c);
    return rc;
}
