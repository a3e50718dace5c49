/* cnc-run: command-line front end of ncpar. */
#include "ncpar/blocks.h"
#include "ncpar/executor.h"
#include "ncpar/feeder.h"
#include "ncpar/lex.h"
#include "ncpar/pipeline.h"
#include "canon_writer.h"
#include "machine.h"
#include "outfile.h"
#include "rs274_ini.h"
#include "run.h"
#include "signals.h"
#include "serve.h"
#include "ncp_version.h"
#include "ncpar/num.h"

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_PROGRAM = 2, EXIT_RUNTIME = 3 };

static void print_diag(const char *prog, const struct ncp_diag *d)
{
    if (d->line)
        fprintf(stderr, "%s:%u:%u: error: %s\n", d->file ? d->file : prog, d->line,
                d->col ? (unsigned)d->col : 1u, d->msg);
    else
        fprintf(stderr, "%s: error: %s\n", d->file ? d->file : prog, d->msg);
}

static void print_waits(const struct ncp_stage_stats *s)
{
    fprintf(stderr, " %llu/%llu/%llu", (unsigned long long)s->empty_waits,
            (unsigned long long)s->full_waits, (unsigned long long)s->sleeps);
}

/* One line per thread: its CPU and wall time, how busy it was and its part of
 * the run's CPU, and how often it found its rings empty or full. The stage
 * with the most CPU time bounds the run; busy well below 100 % is time
 * spent waiting for another stage (or for a CPU on a loaded host). */
static void print_thread(const char *role, int index, const struct ncp_stage_stats *s,
                         double total_cpu)
{
    char name[24];
    if (index >= 0)
        snprintf(name, sizeof name, "%s %d", role, index);
    else
        snprintf(name, sizeof name, "%s", role);
    /* a span under a millisecond (an idle prefaulter) says nothing about load */
    char busy[16] = "    -";
    if (s->wall_ms >= 1.0)
        snprintf(busy, sizeof busy, "%5.1f %%", 100.0 * s->cpu_ms / s->wall_ms);
    double share = total_cpu > 0 ? 100.0 * s->cpu_ms / total_cpu : 0;
    fprintf(stderr,
            "cnc-run: thread %-10s cpu %9.1f ms  sys %8.1f ms  wall %9.1f ms  busy %s  "
            "share %5.1f %%  waits %llu/%llu/%llu\n",
            name, s->cpu_ms, s->sys_ms, s->wall_ms, busy, share,
            (unsigned long long)s->empty_waits,
            (unsigned long long)s->full_waits, (unsigned long long)s->sleeps);
}

static void print_threads(const struct ncp_run_stats *st, const struct ncp_thread_map *map)
{
    if (map->mode == NCP_MODE_SERIAL) {
        print_thread("serial", -1, &st->analyzer, st->analyzer.cpu_ms);
        return;
    }
    int lexers = map->n_lexers < NCP_MAX_LEXERS ? map->n_lexers : NCP_MAX_LEXERS;
    int execs = map->n_executors < NCP_MAX_EXECUTORS ? map->n_executors : NCP_MAX_EXECUTORS;
    int output = !(map->inline_output && map->n_executors == 0);
    double total = st->feeder.cpu_ms + st->analyzer.cpu_ms + (output ? st->output.cpu_ms : 0);
    for (int i = 0; i < lexers; i++)
        total += st->lexer[i].cpu_ms;
    for (int j = 0; j < execs; j++)
        total += st->executor[j].cpu_ms;
    print_thread(lexers ? "feeder" : "prefaulter", -1, &st->feeder, total);
    for (int i = 0; i < lexers; i++)
        print_thread("lexer", i, &st->lexer[i], total);
    print_thread("analyzer", -1, &st->analyzer, total);
    for (int j = 0; j < execs; j++)
        print_thread("executor", j, &st->executor[j], total);
    if (output)
        print_thread("output", -1, &st->output, total);
}

/* The whole process's CPU time (every thread, the main one's start-up and
 * the writer's closing included): what the stage threads do not account for
 * is the rest. */
static void print_process_cpu(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return;
    double user = (double)ru.ru_utime.tv_sec * 1e3 + (double)ru.ru_utime.tv_usec / 1e3;
    double sys = (double)ru.ru_stime.tv_sec * 1e3 + (double)ru.ru_stime.tv_usec / 1e3;
    fprintf(stderr, "cnc-run: process cpu %.1f ms (user %.1f, sys %.1f)\n", user + sys, user,
            sys);
}

/* One summary line, and for the pipeline the CPU time per stage thread: the
 * load balance that decides what more cores can gain. */
static void print_stats(const struct ncp_run_stats *st, const struct ncp_thread_map *map)
{
    int serial = map->mode == NCP_MODE_SERIAL;
    double bps = st->wall_ms > 0 ? (double)st->blocks / (st->wall_ms / 1e3) : 0;
    fprintf(stderr,
            "cnc-run: %llu blocks, %llu commands, %.3f ms (%.3f ms start-up), %.0f blocks/s, "
            "%d threads (%s, %d lexers, %d executors)\n",
            (unsigned long long)st->blocks, (unsigned long long)st->commands, st->wall_ms,
            st->setup_ms, bps, st->threads, ncp_thread_mode_name(map->mode),
            serial ? 0 : map->n_lexers, serial ? 0 : map->n_executors);
    print_threads(st, map);
    if (serial)
        return;
    if (map->n_lexers == 0)
        fprintf(stderr, "cnc-run: cpu ms: feeder %.1f (idle), lexers none "
                "(the analyzer lexes)", st->feeder.cpu_ms);
    else
        fprintf(stderr, "cnc-run: cpu ms: feeder %.1f, lexers", st->feeder.cpu_ms);
    for (int i = 0; i < map->n_lexers && i < NCP_MAX_LEXERS; i++)
        fprintf(stderr, " %.1f", st->lexer[i].cpu_ms);
    fprintf(stderr, ", analyzer %.1f, executors", st->analyzer.cpu_ms);
    for (int j = 0; j < map->n_executors && j < NCP_MAX_EXECUTORS; j++)
        fprintf(stderr, " %.1f", st->executor[j].cpu_ms);
    int inline_out = map->inline_output && map->n_executors == 0;
    if (inline_out)
        fputs(" none, output in the analyzer\n", stderr);
    else
        fprintf(stderr, "%s, output %.1f", map->n_executors ? "" : " none", st->output.cpu_ms);
    if (!inline_out && map->n_lexers == 0 && map->n_executors == 0)
        fprintf(stderr,
                " (lexed %" PRIu64 " of the %" PRIu64 " blocks ahead; the analyzer waited"
                " for it %" PRIu64 " times, slept %" PRIu64 ")",
                st->lexed_ahead, st->blocks, st->ahead_waits, st->ahead_sleeps);
    if (!inline_out)
        fputc('\n', stderr);
    /* who waited for whom: a stage that often finds its input empty is starved,
     * one that finds its output full is ahead of the next */
    fputs("cnc-run: waits empty/full/slept:", stderr);
    if (map->n_lexers > 0) {
        fputs(" feeder", stderr);
        print_waits(&st->feeder);
        fputs(", lexers", stderr);
        for (int i = 0; i < map->n_lexers && i < NCP_MAX_LEXERS; i++)
            print_waits(&st->lexer[i]);
        fputc(',', stderr);
    }
    fputs(" analyzer", stderr);
    print_waits(&st->analyzer);
    if (map->n_executors) {
        fputs(", executors", stderr);
        for (int j = 0; j < map->n_executors && j < NCP_MAX_EXECUTORS; j++)
            print_waits(&st->executor[j]);
    }
    if (!inline_out) {
        fputs(", output", stderr);
        print_waits(&st->output);
    }
    fputc('\n', stderr);
}

/* Why the run had the layout it had, when no flag chose it. */
static void print_choice(const struct ncp_thread_map *map, size_t bytes, int cpus)
{
    size_t from = ncp_auto_parallel_bytes(cpus);
    fprintf(stderr, "cnc-run: layout %s: %zu bytes of program on %d CPU%s; ",
            map->mode == NCP_MODE_SERIAL ? "serial" : "parallel", bytes, cpus,
            cpus == 1 ? "" : "s");
    if (from == SIZE_MAX)
        fputs("threads need 2 CPUs\n", stderr);
    else
        fprintf(stderr, "threads from %zu bytes on\n", from);
}

static void usage(FILE *f)
{
    fputs("usage: cnc-run parse PROG [-j N] [--executors M] [--mode serial|det|att]\n"
          "                          [--config INI] [--tool-table FILE] [--canon FILE|-]\n"
          "                          [--stats] [--max-loops N] [--inline-output]\n"
          "                          [--subroutine-path DIR[:DIR...]] [--ini INI]\n"
          "       cnc-run check PROG [--tool-table FILE] [--subroutine-path DIRS] [--ini INI]\n"
          "       cnc-run run PROG [--config INI] [--trace CSV] [--for SECONDS]\n"
          "                        [--feed-override PCT] [--clock real|virtual]\n"
          "       cnc-run serve [--config INI] [--lcm-url URL] [--clock real|virtual] [--trace CSV]\n"
          "\n"
          "parse  interpret PROG (\"-\" = standard input) with the parallel pipeline and\n"
          "       write canonical machining calls (rs274 -g format) to --canon.\n"
          "       --executors 0: the output thread executes; with --inline-output the\n"
          "       analyzer executes and writes each command itself (no output thread).\n"
          "       -j 0: no lexer threads, the analyzer lexes the text itself.\n"
          "       Default (none of -j, --executors, --mode, --config, --inline-output):\n"
          "       serial for a program too short to pay for starting threads (and on\n"
          "       1 CPU), else det -j 0 --executors 0 on 2 CPUs, -j 2 --executors 1\n"
          "       on more; --stats says which and from what size. --mode det|att\n"
          "       alone: -j 2 --executors 1, on 2 CPUs or fewer -j 0 --executors 0.\n"
          "       `o<name> call` of a sub not defined yet reads name.ngc from the\n"
          "       current folder, then from the --subroutine-path folders (as rs274).\n"
          "       --ini: LinuxCNC's [RS274NGC] as rs274 -i reads it: SUBROUTINE_PATH\n"
          "       (after --subroutine-path) and REMAP lines of M codes to ngc= subs;\n"
          "       run and serve read the same keys from their --config INI.\n"
          "check  report every error in PROG as PROG:LINE:COL: error: message.\n"
          "run    run PROG on the machine: planner, interpolator, position loop, backend\n"
          "       (the simulated servo by default); `cnc-run run --help` for details.\n"
          "serve  the NCK as a service: operator commands, status and events over LCM\n"
          "       (cnc-ctl is its client); `cnc-run serve --help` for details.\n"
          "\n"
          "\n"
          "cnc-run --version prints the version; every command takes --help.\n"
          "exit status: 0 ok, 1 usage, 2 program error, 3 runtime fault\n",
          f);
}

struct parse_opts {
    const char *prog;
    const char *canon;
    const char *config;
    int lexers, executors;
    int inline_output;
    enum ncp_thread_mode mode;
    int mode_given;
    int counts_given;   /* -j or --executors on the command line */
    int stats;
    const char *ini_path;
    struct rs274_ini ini;
    char *sub_path;      /* --subroutine-path and the INI's, joined */
    struct ncp_analyzer_cfg acfg;
};

static int parse_args(int argc, char **argv, struct parse_opts *o)
{
    static const struct option longopts[] = {
        { "jobs", required_argument, 0, 'j' },
        { "executors", required_argument, 0, 'e' },
        { "mode", required_argument, 0, 'm' },
        { "config", required_argument, 0, 'c' },
        { "tool-table", required_argument, 0, 't' },
        { "canon", required_argument, 0, 'o' },
        { "stats", no_argument, 0, 's' },
        { "inline-output", no_argument, 0, 'I' },
        { "max-loops", required_argument, 0, 'L' },
        { "subroutine-path", required_argument, 0, 'P' },
        { "ini", required_argument, 0, 'N' },
        { "help", no_argument, 0, 'h' },
        { 0, 0, 0, 0 },
    };
    int c, v;
    optind = 1;
    while ((c = getopt_long(argc, argv, "j:e:m:c:t:o:shL:IP:", longopts, NULL)) != -1) {
        switch (c) {
        case 'j':
            o->counts_given = 1;
            if (ncp_num_int(optarg, 0, NCP_MAX_LEXERS, &o->lexers))
                return fprintf(stderr, "cnc-run: -j wants 0..%d lexer threads (0: the analyzer lexes)\n", NCP_MAX_LEXERS), -1;
            break;
        case 'e':
            o->counts_given = 1;
            if (ncp_num_int(optarg, 0, NCP_MAX_EXECUTORS, &o->executors))
                return fprintf(stderr, "cnc-run: --executors wants 0..%d (0: the output thread executes)\n", NCP_MAX_EXECUTORS), -1;
            break;
        case 'm':
            o->mode_given = 1;
            if (ncp_thread_mode_parse(optarg, &o->mode))
                return fprintf(stderr, "cnc-run: --mode is serial, det or att\n"), -1;
            break;
        case 'c': o->config = optarg; break;
        case 't': o->acfg.tool_table_path = optarg; break;
        case 'o': o->canon = optarg; break;
        case 'P': o->acfg.subroutine_path = optarg; break;
        case 'N': o->ini_path = optarg; break;
        case 's': o->stats = 1; break;
        case 'I': o->inline_output = 1; break;
        case 'L':
            if (ncp_num_int(optarg, 1, 2000000000, &v))
                return fprintf(stderr, "cnc-run: --max-loops wants a positive count\n"), -1;
            o->acfg.max_loop_iterations = (uint32_t)v;
            break;
        case 'h': usage(stdout); exit(EXIT_OK);
        default: return -1;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "cnc-run: expected exactly one program file\n");
        return -1;
    }
    o->prog = argv[optind];
    if (o->ini_path) {
        if (rs274_ini_load(o->ini_path, &o->ini) != 0)
            return -1;
        if (rs274_ini_apply(&o->ini, &o->acfg, &o->sub_path) != 0)
            return -1;
        o->acfg.ini_given = 1;
    }
    return 0;
}

static void parse_opts_free(struct parse_opts *o)
{
    rs274_ini_free(&o->ini);
    free(o->sub_path);
}

/* The files a run reads: none of them may be an output. */
static int program_ids(const struct ncp_source *src, const struct parse_opts *o,
                       struct ncp_file_id *ids)
{
    int n = 0;
    if (src->ino) {
        ids[n].dev = src->dev;
        ids[n].ino = src->ino;
        ids[n++].what = "the program";
    }
    n = ncp_file_id_add(ids, n, o->config, "the thread map INI");
    n = ncp_file_id_add(ids, n, o->acfg.tool_table_path, "the tool table");
    n = ncp_file_id_add(ids, n, o->ini_path, "the INI");
    return n;
}

static int parse_run(struct parse_opts *o, int argc, char **argv)
{
    o->lexers = 2;
    o->executors = 1;
    o->mode = NCP_MODE_DET;
    if (parse_args(argc, argv, o))
        return usage(stderr), EXIT_USAGE;
    if (ncp_cli_check_tool_table(o->acfg.tool_table_path))
        return EXIT_USAGE;

    struct ncp_thread_map map;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int cpus = ncp_cpus_usable();
    /* no flag names a layout: it is chosen from the program's size once the
     * program is read (a pipe is read to its end before the run) */
    int automatic = !o->config && !o->mode_given && !o->counts_given && !o->inline_output;
    if (o->config) {
        if (ncp_thread_map_load(&map, o->config, &d) != NCP_OK) {
            if (d.line)
                fprintf(stderr, "%s:%u: error: %s\n", o->config, d.line, d.msg);
            else
                fprintf(stderr, "%s: error: %s\n", o->config, d.msg);
            return EXIT_USAGE;
        }
        if (o->mode_given)
            map.mode = o->mode;
    } else if (!automatic) {
        /* --mode without counts on two CPUs or fewer: the two-thread layout
         * of ncp_thread_map_auto */
        if (!o->counts_given && cpus <= 2) {
            o->lexers = 0;
            o->executors = 0;
        }
        ncp_thread_map_default(&map, o->mode, o->lexers, o->executors);
    }
    if (!automatic && o->inline_output) {
        if (map.n_executors > 0) {
            fprintf(stderr, "cnc-run: --inline-output needs --executors 0 (the analyzer then executes)\n");
            return EXIT_USAGE;
        }
        map.inline_output = 1;
    }

    struct ncp_source src;
    if (ncp_source_open(&src, o->prog, &d) != NCP_OK) {
        print_diag(o->prog, &d);
        return EXIT_PROGRAM;
    }
    size_t prog_bytes = src.end - src.begin;
    if (automatic)
        ncp_thread_map_auto(&map, prog_bytes, cpus);
    struct ncp_file_id inputs[5];
    int n_inputs = program_ids(&src, o, inputs);
    struct canon_writer *w = NULL;
    if (o->canon && !(w = canon_writer_open(o->canon, inputs, n_inputs))) {
        ncp_source_close(&src);
        return EXIT_USAGE;
    }
    ncp_cli_catch_input_faults(o->prog, 1);
    struct ncp_output out = { .ctx = w, .emit = canon_writer_emit,
                              .reserve = canon_writer_reserve, .commit = canon_writer_commit };
    struct ncp_run_stats st;
    memset(&st, 0, sizeof st);
    int rc = map.mode == NCP_MODE_SERIAL
                 ? ncp_serial_run(&src, &o->acfg, &out, &st, &d)
                 : ncp_pipeline_run(&src, &map, &o->acfg, &out, &st, &d);
    int status = EXIT_OK;
    uint32_t warnings = st.warnings;
    const char *warning;
    while ((warning = ncp_run_warning_next(&warnings)) != NULL)
        fprintf(stderr, "cnc-run: warning: %s\n", warning);
    /* a program that changed under the run gives no output that could be
     * taken for its own */
    int changed = ncp_source_changed(&src);
    int write_err = w ? canon_writer_close(w, !changed) : 0;
    if (changed) {
        fprintf(stderr, "%s: error: input changed while reading\n", o->prog);
        status = EXIT_PROGRAM;
        write_err = 0;
        rc = NCP_OK;
    }
    if (write_err) {
        /* the text could not be written (disk full, closed pipe): a fault of
         * the machine, not of the program, which stopped at that point */
        fprintf(stderr, "cnc-run: error writing canonical output: %s\n", strerror(write_err));
        status = EXIT_RUNTIME;
    }
    if (rc != NCP_OK && !(write_err && rc == NCP_ERR_IO)) {
        print_diag(o->prog, &d);
        status = EXIT_PROGRAM;
    }
    if (o->stats) {
        print_stats(&st, &map);
        if (automatic)
            print_choice(&map, prog_bytes, cpus);
    }
    ncp_source_close(&src);
    if (o->stats)
        print_process_cpu(); /* after the text is written out and the input let go */
    return status;
}

static int cmd_parse(int argc, char **argv)
{
    struct parse_opts o;
    memset(&o, 0, sizeof o);
    int rc = parse_run(&o, argc, argv);
    parse_opts_free(&o);
    return rc;
}

/* Syntax errors are independent of each other, so check reports every one of
 * them; the interpreter itself stops at its first error, which is reported too
 * unless it is one of the syntax errors already listed. */
static int check_run(struct parse_opts *o, int argc, char **argv)
{
    if (parse_args(argc, argv, o))
        return usage(stderr), EXIT_USAGE;
    if (ncp_cli_check_tool_table(o->acfg.tool_table_path))
        return EXIT_USAGE;
    struct ncp_source src;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (ncp_source_open(&src, o->prog, &d) != NCP_OK) {
        print_diag(o->prog, &d);
        return EXIT_PROGRAM;
    }
    ncp_cli_catch_input_faults(o->prog, 0);
    struct ncp_run_stats st;
    int rc = ncp_serial_run(&src, &o->acfg, NULL, &st, &d);
    struct ncp_block *b = malloc(sizeof *b);
    struct ncp_blocks_lines lines;
    struct ncp_span sp;
    int errors = 0, printed_run_error = 0, bad;
    ncp_blocks_lines_start(&lines, &src);
    /* '%' lines are tape delimiters, not blocks: the customary one after M2
     * is never read, one the run does read is its error; U and W words are
     * good in a G70-G72 profile, and a bad character anywhere else: only the
     * run knows, and reports that case */
    while (b && ncp_blocks_check_next(&lines, &sp, b, &bad) == 0) {
        if (rc != NCP_OK && !printed_run_error && d.line <= sp.line) {
            print_diag(o->prog, &d);
            printed_run_error = 1;
            errors++;
            if (d.line == sp.line)
                continue;
        }
        if (bad) {
            print_diag(o->prog, &b->err);
            errors++;
        }
    }
    if (rc != NCP_OK && !printed_run_error) {
        print_diag(o->prog, &d);
        errors++;
    }
    free(b);
    if (ncp_source_changed(&src)) {
        fprintf(stderr, "%s: error: input changed while reading\n", o->prog);
        errors++;
    }
    ncp_source_close(&src);
    return errors ? EXIT_PROGRAM : EXIT_OK;
}

static int cmd_check(int argc, char **argv)
{
    struct parse_opts o;
    memset(&o, 0, sizeof o);
    int rc = check_run(&o, argc, argv);
    parse_opts_free(&o);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (!strcmp(argv[1], "parse"))
        return cmd_parse(argc - 1, argv + 1);
    if (!strcmp(argv[1], "check"))
        return cmd_check(argc - 1, argv + 1);
    if (!strcmp(argv[1], "run"))
        return ncp_cli_run(argc - 1, argv + 1);
    if (!strcmp(argv[1], "serve"))
        return ncp_cli_serve(argc - 1, argv + 1);
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return EXIT_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("cnc-run (ncpar) %s\n", NCP_VERSION);
        return EXIT_OK;
    }
    fprintf(stderr, "cnc-run: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return EXIT_USAGE;
}
