/* Data analyzer: the one sequential stage. Consumes parsed blocks in program
 * order, applies modal state, parameters, expressions, O-word control flow and the
 * cutter-compensation decisions, and emits numbered command slots. */
#ifndef NCPAR_ANALYZER_H
#define NCPAR_ANALYZER_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "ncpar/blocks.h"
#include "ncpar/canon.h"
#include "ncpar/diag.h"
#include "ncpar/feeder.h"
#include "ncpar/lex.h"

/* Where command slots go, in cmd_id order. acquire() returns a slot whose header
 * (n_ops, flags, diag.code, text_used, out_len) is zeroed; ops are NOT cleared, so
 * the analyzer writes each op whole (compound literal: unused fields 0). It may
 * block while the ring is full; NULL = shut down. publish() hands it on. */
struct ncp_cmd_sink {
    void *ctx;
    struct ncp_cmd *(*acquire)(void *ctx);
    void (*publish)(void *ctx, struct ncp_cmd *cmd);
};

struct ncp_tool_entry {
    int pocket;
    double z_offset, x_offset, diameter, frontangle, backangle;
    int orientation;
};

#define NCP_MAX_TOOLS 1000

/* Reads a LinuxCNC tool table as the interpreter will and writes a warning
 * "PATH:LINE: warning: ..." to warn (if not NULL) for each line the
 * interpreter skips (rs274: "Unrecognized line skipped"). A table that cannot
 * be read (missing, a directory) is an error in d. */
int ncp_tool_table_check(const char *path, FILE *warn, struct ncp_diag *d);

/* LinuxCNC's parameter file ([RS274NGC] PARAMETER_FILE, the ".var" file):
 * one "NUMBER<TAB>VALUE" line per parameter, numbers ascending. The
 * persistent ones are always in it (ncp_var_persistent: #5161-#5169 and
 * #5181-#5189, G28/G30; #5210-#5219, G92 applied and its offsets; #5220, the
 * coordinate system; #5221-#5230 .. #5381-#5390, G54..G59.3 with R); any
 * other number a file lists is kept too, as LinuxCNC does. Values are in
 * the interpreter's user unit (inch, as the tool table's). */
#define NCP_VAR_PARAMS 5602      /* #1..#5601, as rs274 */
struct ncp_var_file {
    double value[NCP_VAR_PARAMS];
    unsigned char listed[NCP_VAR_PARAMS]; /* written back */
};
int ncp_var_persistent(int index);
/* No file yet: the persistent numbers listed, G54 (#5220 = 1), the rest 0. */
void ncp_var_file_init(struct ncp_var_file *vf);
/* A missing file is the defaults (*existed = 0); a line that is not
 * "NUMBER VALUE" (a number 1..5601, ascending, a finite value; #5220 one of
 * 1..9) is NCP_ERR_SEMANTIC with its line in d->line and why in d->msg. */
int ncp_var_file_read(const char *path, struct ncp_var_file *vf, int *existed,
                      struct ncp_diag *d);
/* The text of the file (malloc'd, *len its length), and the whole file
 * written by temporary file, fsync and rename (never torn). */
char *ncp_var_file_text(const struct ncp_var_file *vf, size_t *len);
int ncp_var_file_write(const char *path, const struct ncp_var_file *vf, struct ncp_diag *d);

#define NCP_DEFAULT_MAX_LOOPS 10000000u

/* One key of a LinuxCNC INI, which a program reads as #<_ini[SECTION]KEY>
 * (rs274 -i with [RS274NGC]INI_VARS, on by default). */
struct ncp_ini_var {
    const char *section, *key, *value;
};

/* One REMAP line of LinuxCNC's [RS274NGC] section ("M400 modalgroup=10
 * argspec=Pq ngc=m400"): its text after "REMAP =", and where it was read,
 * for the errors that name it. */
struct ncp_remap_line {
    const char *text;
    const char *file;
    uint32_t line;
};

struct ncp_analyzer_cfg {
    const char *tool_table_path; /* NULL: empty table (as rs274 without -t) */
    uint32_t max_loop_iterations;/* runaway guard for while/do/repeat loops and the passes
                                    of one G76 cycle, 0 = NCP_DEFAULT_MAX_LOOPS */
    uint32_t max_call_depth;     /* O-word call nesting, 0 = default (rs274: 10) */
    /* Where `o<name> call` looks for name.ngc when no sub of that name was
     * defined yet: the current folder, then these (colon-separated), as
     * rs274 with [RS274NGC]SUBROUTINE_PATH. NULL: the current folder only. */
    const char *subroutine_path;
    /* REMAP lines (as rs274 -i reads them): M codes whose meaning becomes an
     * O-word subroutine. None (0): no remapping, and no cost for it. */
    const struct ncp_remap_line *remaps;
    int n_remaps;
    /* [RS274NGC]OWORD_NARGS: a called sub has #<n_args>, the number of
     * its arguments (read-only), as rs274 -i gives it */
    int oword_nargs;
    /* [RS274NGC]ORIENT_OFFSET: degrees added to M19's R (or M19 P's angle
     * without R), as rs274 -i adds them */
    double orient_offset;
    /* [RS274NGC]DISABLE_FANUC_STYLE_SUB: M98, M99 and bare O-word lines
     * are refused, as rs274 -i refuses them */
    int no_fanuc_subs;
    /* rs274 run with an INI (-i) closes with one ON_RESET, not two */
    int ini_given;
    /* the INI's keys for #<_ini[SECTION]KEY> (read-only; none: undefined) */
    const struct ncp_ini_var *ini_vars;
    int n_ini_vars;
    /* The NCK's resident interpreter: modal state, parameters, offsets and
     * tool carry over from one run to the next (programs and MDI lines run one
     * after another, as on a controller), so a run emits no rs274 start-up
     * calls and no closing resets, and the end of the text without M2/M30 is
     * an ordinary end (an MDI line). */
    int resident;
    /* ncp_serial_run / ncp_pipeline_run: run on this analyzer (made with
     * resident set, owned by the caller) instead of a new one. */
    struct ncp_analyzer *instance;
    /* The NCK: an M66 emits WAIT_INPUT for the machine, whose result
     * (#5399) the interpreter reads back at a queue buster (see
     * ncp_machine_sync). 0 (parse, check): no call, rs274 -g's stand-in. */
    int m66_on_machine;
    /* The machine's M100..M199 (LinuxCNC's user M codes): folders, ':'
     * between them, searched in order for an executable file M1nn when the
     * interpreter is made. A code found there becomes a USER_M call, which
     * the NCK runs with the machine at rest; one not found is refused as
     * rs274 refuses it ("Unknown m code used"). NULL (parse, check: rs274 -g
     * runs none): every one is refused. */
    const char *user_m_dirs;
    /* A stop request (a signal, an operator's abort), asked every 64
     * blocks the interpreter reads, laps of loops and skipped lines
     * included (well under a millisecond): nonzero ends the run there with
     * NCP_ERR_LIMIT "stopped on request", rather than after a loop's
     * millions of laps or a long file's last line. Called from the
     * interpreter's thread: it must be cheap (an atomic load). NULL: never
     * asked. */
    int (*cancel)(void *ctx);
    void *cancel_ctx;
    /* LinuxCNC's parameter file (cnc-run run): the interpreter starts from
     * these values as rs274 does from its .var file (the coordinate system
     * of #5220 with its offsets and rotation, G92 when #5210 says it is
     * applied, the machine's zero as the current point), and on its free
     * copies the persistent parameters' last values to params_out. NULL:
     * rs274's defaults, nothing copied. */
    const struct ncp_var_file *params_in;
    struct ncp_var_file *params_out;
    /* With params_in: the machine's point (X Y Z A B C U V W, machine coordinates,
     * mm) the current point starts at instead of the machine's zero, for a
     * run that starts where a machine stands (the NCK's load estimate).
     * NULL: the machine's zero. */
    const double *start_machine;
    /* cnc-run run: on its free the tool table (after G10 L1, L10, L11)
     * becomes tools_out's, to be written back as serve does (NULL: none) */
    struct ncp_analyzer *tools_out;
};

/* Queue busters. The interpreter runs far ahead of motion; after a G38.x
 * probe, an M66 or an M6 (which may move to the tool change position) it
 * cannot know the machine's result. When the run's
 * output is a machine (ncp_output.sync), the analyzer stops at the first
 * read after such a call (the next block, or a parameter read on an O-word
 * line), hands on every command made so far and asks the machine, which
 * answers once its motion up to the call has finished. Without a machine
 * (parse, check) nothing waits and rs274 -g's stand-in values hold. */
enum ncp_sync_what { NCP_SYNC_PROBE = 1, NCP_SYNC_INPUT = 2, NCP_SYNC_POSITION = 4 };
struct ncp_machine_sync {
    int what;                  /* enum ncp_sync_what bits the machine filled */
    /* a probe, in program coordinates and units: the trip point (#5061..),
     * whether it tripped (#5070) and where the axes came to rest */
    double probed[6];
    int tripped;
    double pos[3];             /* (and after an M6: NCP_SYNC_POSITION) */
    double input;              /* M66: #5399 */
};
/* Returns 0 with ms filled, or non-zero when the run is being stopped. */
typedef int (*ncp_machine_sync_fn)(void *ctx, struct ncp_machine_sync *ms);

/* The executable file M<code> (100..199) in the first of dirs (':' between
 * folders) that has one, as LinuxCNC's task finds it: its path in out, 0;
 * -1 when none has it (or it does not fit out). A file that is not
 * executable is passed over. */
int ncp_user_m_find(const char *dirs, int code, char *out, size_t len);

struct ncp_analyzer;

struct ncp_analyzer *ncp_analyzer_new(const struct ncp_analyzer_cfg *cfg,
                                      struct ncp_diag *d);
void ncp_analyzer_free(struct ncp_analyzer *a);

/* Run to the end of the program or the first error. Every slot is published, the
 * last one with NCP_CMD_F_END or NCP_CMD_F_ERROR set (an error is carried by a
 * slot so that it comes out in program order). Returns NCP_OK, or the error code. */
int ncp_analyzer_run(struct ncp_analyzer *a, const struct ncp_block_feed *feed,
                     const struct ncp_cmd_sink *sink);

/* Between runs of a resident analyzer: the machine moved without it (a
 * stopped program, a jog, homing), so its current point becomes pos (X Y Z in
 * program coordinates and units: see ncp_canon_map_to_program). */
void ncp_analyzer_set_position(struct ncp_analyzer *a, const double pos[3]);

/* Between runs of a resident analyzer: numbered parameter #index (1..5601;
 * 0 outside), and setting one as the parameter file gives it. After
 * setting the frame parameters (#5210-#5390), the analyzer takes them into
 * its state only when a block selects a system or restores G92 (the NCK
 * runs "G92.3" and "G5x" lines to do so, as rs274's start-up would). */
double ncp_analyzer_param(const struct ncp_analyzer *a, int index);
void ncp_analyzer_set_param(struct ncp_analyzer *a, int index, double v);

/* The tool table file's text with the interpreter's entries (after G10 L1,
 * L10, L11): a line whose tool changed is written anew in LinuxCNC's form
 * ("T1 P1 Z+0.511000 D0.125000 ;its comment"), every other line (comments,
 * blank, skipped, unchanged tools) byte for byte. Changed: against base's
 * entry (an analyzer holding the table as last loaded or written), or
 * with base NULL against the line itself. *changed: 0 when the text is the
 * old one. malloc'd; NULL out of memory. */
char *ncp_analyzer_tool_table_text(const struct ncp_analyzer *a, const struct ncp_analyzer *base,
                                   const char *old, size_t len, size_t *out_len, int *changed);
/* Reads path, and writes it whole (temporary file, fsync, rename) when the
 * interpreter's entries changed it; *written says so. NCP_OK or NCP_ERR_IO. */
int ncp_analyzer_save_tool_table(const struct ncp_analyzer *a, const struct ncp_analyzer *base,
                                 const char *path, int *written, struct ncp_diag *d);
/* dst's tool table becomes src's (the baseline after a write). */
void ncp_analyzer_copy_tools(struct ncp_analyzer *dst, const struct ncp_analyzer *src);
/* 1 when a's tool entries are b's as the file would write them (a save of
 * a against b would change no line), else 0. Reads memory only. */
int ncp_analyzer_same_tools(const struct ncp_analyzer *a, const struct ncp_analyzer *b);

/* The modal codes in force (what every slot is stamped with when handed on);
 * for a resident analyzer between runs, the state the next run starts in. */
void ncp_analyzer_active_codes(const struct ncp_analyzer *a, struct ncp_active_codes *out);

/* The machine a run's busters wait for (the pipeline sets it for a run whose
 * output has one; NULL: none, rs274 -g's stand-ins). */
void ncp_analyzer_set_sync(struct ncp_analyzer *a, ncp_machine_sync_fn fn, void *ctx);

#endif
