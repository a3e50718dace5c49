/* Subroutine files (ncpar/blocks.h): `o<name> call` of a sub not defined yet
 * makes rs274 look for name.ngc in the current folder, then in each folder
 * of its subroutine path. A file found is read whole, once, and keeps its
 * number for the run: a second call of a sub it defines finds the label. */
#include "ncpar/blocks.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

struct sub_file {
    struct ncp_source src;
    const char *name;                 /* ncp_diag_file_of_tag(tag) */
    unsigned tag;                     /* its ncp_diag_file_tag */
};

struct ncp_sub_files {
    struct sub_file file[NCP_SUB_FILES_MAX]; /* numbers 1 .. n */
    uint32_t n;
};

struct ncp_sub_files *ncp_sub_files_new(void)
{
    return calloc(1, sizeof(struct ncp_sub_files));
}

void ncp_sub_files_free(struct ncp_sub_files *t)
{
    if (!t)
        return;
    for (uint32_t k = 0; k < t->n; k++)
        ncp_source_close(&t->file[k].src);
    free(t);
}

/* A regular file that can be read: a folder of the name or no file at all
 * is not one (rs274 opens with fopen, which a folder does not pass for reading). */
static int sub_files_readable(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

int ncp_sub_files_open(struct ncp_sub_files *t, const char *name, size_t name_len,
                       const char *sub_path, uint32_t line, uint16_t col, uint32_t *file,
                       struct ncp_diag *d)
{
    char path[4096];
    const char *dirs = sub_path ? sub_path : "";
    const char *dir = "";
    size_t dir_len = 0;
    *file = 0;
    for (;;) {
        int n = dir_len ? snprintf(path, sizeof path, "%.*s/%.*s.ngc", (int)dir_len, dir,
                                   (int)name_len, name)
                        : snprintf(path, sizeof path, "%.*s.ngc", (int)name_len, name);
        if (n > 0 && (size_t)n < sizeof path && sub_files_readable(path))
            break;
        if (*dirs == '\0')
            return NCP_OK;
        dir = dirs;
        const char *colon = strchr(dirs, ':');
        dir_len = colon ? (size_t)(colon - dirs) : strlen(dirs);
        dirs = colon ? colon + 1 : dirs + dir_len;
    }
    for (uint32_t k = 1; k <= t->n; k++)
        if (strcmp(t->file[k - 1].name, path) == 0) {
            *file = k;
            return NCP_OK;
        }
    if (t->n >= NCP_SUB_FILES_MAX)
        return ncp_diag_set(d, NCP_ERR_LIMIT, line, col,
                            "more than %d subroutine files called", NCP_SUB_FILES_MAX);
    struct sub_file *nf = &t->file[t->n];
    nf->tag = ncp_diag_file_tag(path);
    nf->name = ncp_diag_file_of_tag(nf->tag);
    if (!nf->name)
        return ncp_diag_set(d, NCP_ERR_IO, line, 0, "out of memory");
    struct ncp_diag od;
    if (ncp_source_open(&nf->src, nf->name, &od) != NCP_OK)
        return ncp_diag_set(d, NCP_ERR_IO, line, col, "Unable to open file <%s>: %s",
                            nf->name, od.msg);
    *file = ++t->n;
    return NCP_OK;
}

const struct ncp_source *ncp_sub_files_src(const struct ncp_sub_files *t, uint32_t file)
{
    return &t->file[file - 1].src;
}

const char *ncp_sub_files_name(const struct ncp_sub_files *t, uint32_t file)
{
    return t->file[file - 1].name;
}

unsigned ncp_sub_files_tag(const struct ncp_sub_files *t, uint32_t file)
{
    return t->file[file - 1].tag;
}
