/* Exact fixed-point text of a double (num_text.h). */
#include "num_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int ncp_num_text(char *out, size_t len, double v, int plus)
{
    v += 0.0;   /* -0 becomes 0: no "-0.000000" */
    for (int prec = 6; prec <= 20; prec++) {
        int n = snprintf(out, len, plus ? "%+.*f" : "%.*f", prec, v);
        if (n > 0 && (size_t)n < len && fabs(strtod(out, NULL) - v) <= 1e-12 * fmax(1, fabs(v)))
            return n;
    }
    return snprintf(out, len, plus ? "%+.17g" : "%.17g", v);
}
