/* Private to the core: formatted output into a caller's buffer that measures what it would need (the
 * snprintf convention), shared by the config and table writers. */
#ifndef HM_CORE_TEXTSINK_H
#define HM_CORE_TEXTSINK_H

#include <stddef.h>

typedef struct {
  char *buf;   /* may be NULL when len == 0 (size query) */
  size_t len;  /* capacity of buf */
  size_t used; /* characters produced so far (possibly more than len) */
} hm_text_sink;

/* Append printf-style text; what does not fit is counted but not written. */
void hm_text_sink_printf(hm_text_sink *s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#endif
