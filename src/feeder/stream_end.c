/* Where a program read from a pipe ends (stream_end.h). */
#include "stream_end.h"

#include "ncpar/feeder.h"
#include "ncpar/lex.h"

#include <string.h>

/* The '%' line test (ncpar/feeder.h) lives here, at the bottom of the
 * feeder: the block splitter (source.c) calls this scan and the test, and
 * this file calls nothing of source.c back. */
int ncp_source_percent_line(const char *s, size_t n)
{
    size_t i = 0;
    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        i++;
    return i < n && s[i] == '%';
}

static int is_blank(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (s[i] != ' ' && s[i] != '\t' && s[i] != '\r')
            return 0;
    return 1;
}

/* The interpreter must reach what comes next: nothing is open around it and
 * no call can jump elsewhere. */
static int reached(const struct ncp_stream_end *e)
{
    return !e->calls && e->depth == 0;
}

/* The line as the lexer sees it, roughly: lower case, no blanks, no
 * comments. n < NCP_LINE_MAX. */
static void squeeze(const char *s, size_t n, char *out)
{
    size_t k = 0;
    int paren = 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (paren) {
            paren = c != ')';
            continue;
        }
        if (c == '(') {
            paren = 1;
            continue;
        }
        if (c == ';')
            break;
        if (c == ' ' || c == '\t' || c == '\r')
            continue;
        out[k++] = c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c;
    }
    out[k] = 0;
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* An M word of value 2 or 30 on the line (outside <named> parameters). */
static int ends_program(const char *p)
{
    for (; *p; p++) {
        if (*p == '<') {
            const char *gt = strchr(p, '>');
            if (!gt)
                return 0;
            p = gt;
            continue;
        }
        if (*p != 'm' || !is_digit(p[1]))
            continue;
        const char *q = p + 1;
        while (*q == '0')
            q++;
        int v = 0;
        while (is_digit(*q) && v < 1000)
            v = v * 10 + (*q++ - '0');
        if (*q == '.') {
            q++;
            while (*q == '0')
                q++;
            if (is_digit(*q))
                continue;
        }
        if (v == 2 || v == 30)
            return 1;
    }
    return 0;
}

static void lost(struct ncp_stream_end *e)
{
    e->calls = 1;
}

static void push(struct ncp_stream_end *e, char kind, const char *label, size_t n)
{
    if (e->depth >= NCP_STREAM_END_DEPTH || n >= sizeof e->label[0]) {
        lost(e);
        return;
    }
    e->kind[e->depth] = kind;
    memcpy(e->label[e->depth], label, n);
    e->label[e->depth][n] = 0;
    e->depth++;
}

static void pop(struct ncp_stream_end *e)
{
    if (e->depth == 0)
        lost(e);
    else
        e->depth--;
}

static int keyword(const char *p, const char *word)
{
    size_t n = strlen(word);
    return strncmp(p, word, n) == 0 && !(p[n] >= 'a' && p[n] <= 'z');
}

/* An o-word line (p after the 'o'): the blocks it opens and closes. */
static void oword(struct ncp_stream_end *e, const char *p)
{
    const char *label = p;
    if (*p == '<') {
        const char *gt = strchr(p, '>');
        if (!gt)
            return lost(e);
        p = gt + 1;
    } else {
        while (is_digit(*p))
            p++;
    }
    size_t n = (size_t)(p - label);
    if (n == 0)
        return lost(e);
    if (keyword(p, "sub") || keyword(p, "if") || keyword(p, "repeat"))
        push(e, 'b', label, n);
    else if (keyword(p, "do"))
        push(e, 'd', label, n);
    else if (keyword(p, "while")) {
        /* the end of a do ... while, or a while loop of its own */
        if (e->depth > 0 && e->kind[e->depth - 1] == 'd' &&
            strlen(e->label[e->depth - 1]) == n && !memcmp(e->label[e->depth - 1], label, n))
            pop(e);
        else
            push(e, 'b', label, n);
    } else if (keyword(p, "endsub") || keyword(p, "endif") || keyword(p, "endwhile") ||
               keyword(p, "endrepeat"))
        pop(e);
    else if (!keyword(p, "else") && !keyword(p, "elseif") && !keyword(p, "break") &&
             !keyword(p, "continue") && !keyword(p, "return"))
        lost(e);  /* a call, or something this reader does not know */
}

/* 1 when the program certainly ends with this complete line. */
static int line_ends(struct ncp_stream_end *e, const char *s, size_t n)
{
    if (!e->started) {
        if (is_blank(s, n))
            return 0;
        e->started = 1;
        if (ncp_source_percent_line(s, n)) {
            e->percent = 1;
            return 0;
        }
    }
    if (e->percent && ncp_source_percent_line(s, n))
        return 1;
    if (n >= NCP_LINE_MAX)
        return reached(e);  /* "Command too long" there */
    char q[NCP_LINE_MAX + 1];
    squeeze(s, n, q);
    const char *p = q;
    if (*p == '/')
        return 0;   /* block delete may skip it */
    if (*p == 'n')
        for (p++; is_digit(*p) || *p == '.'; p++)
            ;
    if (*p == 'o') {
        oword(e, p + 1);
        return 0;
    }
    if (strstr(p, "m98"))
        lost(e);
    return reached(e) && ends_program(p);
}

size_t ncp_stream_end_scan(void *ctx, const char *text, size_t len)
{
    struct ncp_stream_end *e = ctx;
    while (e->off < len) {
        const char *s = text + e->off;
        const char *nl = memchr(s, '\n', len - e->off);
        if (!nl) {
            /* a line already too long to lex: the run stops there */
            size_t tail = len - e->off;
            if (tail > NCP_LINE_MAX && reached(e) &&
                (e->started || (!is_blank(s, NCP_LINE_MAX) && !ncp_source_percent_line(s, tail))))
                return len;
            return 0;
        }
        size_t n = (size_t)(nl - s);
        e->off += n + 1;
        if (line_ends(e, s, n))
            return e->off;
    }
    return 0;
}
