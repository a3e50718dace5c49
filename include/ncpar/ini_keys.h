/* The machine INI's sections and keys: every one the reader
 * (ncp_machine_cfg_load, src/motion/config.c) takes, with the values it
 * takes, its default and its meaning.
 *
 * Invariant: the reader refuses a key this table does not list before it
 * looks at its value, and ncpar.ini(5) is printed from this table by a tool
 * (tools/ini-man.c) that first loads a probe INI for each row through the
 * reader and stops the build when the reader refuses a value the row allows
 * or takes one it rules out. So the page and the reader cannot disagree
 * about which keys exist, nor about their ranges.
 *
 * A section or key name may hold one placeholder: <L> an axis letter of
 * XYZABCUVW, <n> a whole number (the reader bounds it). */
#ifndef NCPAR_INI_KEYS_H
#define NCPAR_INI_KEYS_H

#include <stddef.h>

enum ncp_ini_kind {
    NCP_INI_REAL,   /* a plain decimal in [lo, hi] */
    NCP_INI_INT,    /* a whole number in [lo, hi] */
    NCP_INI_CPU,    /* a CPU of this machine, -1 (the OS chooses) .. the last one */
    NCP_INI_WORD,   /* one of the words in values, '|' between them, any case */
    NCP_INI_TEXT,   /* free form: values says which */
};

struct ncp_ini_key {
    const char *section;
    const char *key;
    enum ncp_ini_kind kind;
    double lo, hi;          /* REAL and INT */
    const char *unit;       /* "" when it has none */
    const char *values;     /* WORD: the words; TEXT: the form; else NULL */
    const char *def;        /* the default as a file would write it; NULL: required
                               (or no value when it is not given: doc says) */
    const char *example;    /* TEXT: a value the reader takes; else NULL */
    const char *probe_section; /* the section a probe puts it in, when the
                                  placeholder's first choice cannot hold it */
    const char *doc;
};

struct ncp_ini_section {
    const char *name;
    const char *doc;
};

extern const struct ncp_ini_key ncp_ini_keys[];
extern const size_t ncp_ini_n_keys;
extern const struct ncp_ini_section ncp_ini_sections[];
extern const size_t ncp_ini_n_sections;

/* The row of [sec] key (names in any case, '-' as '_'), or NULL. */
const struct ncp_ini_key *ncp_ini_key_find(const char *sec, const char *key);

#endif
