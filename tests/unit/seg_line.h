/* A programmed line as the canon map would hand it to a stage, for the tests
 * that feed segments straight into the planner's or ADCAI's stages. Include
 * after ncpar/motion.h (or a header that includes it). */
#ifndef NCP_TEST_SEG_LINE_H
#define NCP_TEST_SEG_LINE_H

#include <string.h>

static struct ncp_seg line_seg(const double a[3], const double b[3], double feed, int term)
{
    struct ncp_seg s;
    memset(&s, 0, sizeof s);
    s.kind = NCP_SEG_LINE;
    s.term = (uint8_t)term;
    s.line = 1;
    memcpy(s.start, a, 3 * sizeof(double));
    memcpy(s.end, b, 3 * sizeof(double));
    ncp_seg_set_length(&s);
    s.feed = feed;
    return s;
}

#endif
