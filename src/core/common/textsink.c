#include "textsink.h"

#include <stdarg.h>
#include <stdio.h>

void hm_text_sink_printf(hm_text_sink *s, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  char *dst = s->used < s->len ? s->buf + s->used : NULL;
  const int n = vsnprintf(dst, dst ? s->len - s->used : 0, fmt, ap);
  va_end(ap);
  if (n > 0) s->used += (size_t)n;
}
