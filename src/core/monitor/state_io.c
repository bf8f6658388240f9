/* The state file: state.h's record written atomically beside the previous one, and read back (see state.h). */
#define _POSIX_C_SOURCE 200809L /* fsync, O_CLOEXEC, O_DIRECTORY */
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hunting_monitor/state.h"

enum { PATH_BYTES = 4096, FILE_MAX_BYTES = 1 << 20 };

/* Text into out[len], cut to fit (paths are long, the outcome's text is not). */
static void say(char *out, size_t len, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(out, len, fmt, ap);
  va_end(ap);
}

/* path with a suffix into out; 0 if it does not fit */
static int suffixed(const char *path, const char *suffix, char *out, size_t len) {
  const int n = snprintf(out, len, "%s%s", path, suffix);
  return n > 0 && (size_t)n < len;
}

static hm_status io_error(char *why, size_t len, const char *path, const char *what) {
  if (why && len) say(why, len, "%s: %s: %s", path, what, strerror(errno));
  return HM_EIO;
}

/* All of bytes into fd, through partial writes and interruptions. */
static int write_all(int fd, const unsigned char *bytes, size_t n) {
  while (n > 0) {
    const ssize_t k = write(fd, bytes, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return -1;
    bytes += k;
    n -= (size_t)k;
  }
  return 0;
}

/* The renames into path's directory made durable (a file system that cannot sync a directory is left as it is). */
static int sync_directory(const char *path) {
  char dir[PATH_BYTES];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (!slash) snprintf(dir, sizeof dir, ".");
  else if (slash == dir) slash[1] = '\0';
  else *slash = '\0';
  const int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return -1;
  const int rc = fsync(fd) == 0 || errno == EINVAL || errno == EROFS ? 0 : -1;
  close(fd);
  return rc;
}

hm_status hm_state_save_file(const hm_monitor m, const char *path, double now_s, double written_unix_s, char *why,
                             size_t len) {
  if (!m || !path || !*path) return HM_EINVAL;
  unsigned char buf[HM_STATE_MAX_BYTES];
  size_t n = 0;
  const hm_status st = hm_state_save(m, now_s, written_unix_s, buf, sizeof buf, &n);
  if (st != HM_OK) {
    if (why && len) say(why, len, "%s: the state could not be made: %s", path, hm_status_str(st));
    return st;
  }
  char tmp[PATH_BYTES], prev[PATH_BYTES];
  if (!suffixed(path, ".tmp", tmp, sizeof tmp) || !suffixed(path, ".prev", prev, sizeof prev)) {
    errno = ENAMETOOLONG;
    return io_error(why, len, path, "the path");
  }
  const int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return io_error(why, len, tmp, "cannot create");
  if (write_all(fd, buf, n) != 0 || fsync(fd) != 0) {
    const int e = errno;
    close(fd);
    unlink(tmp);
    errno = e;
    return io_error(why, len, tmp, "cannot write");
  }
  if (close(fd) != 0) return io_error(why, len, tmp, "cannot close");
  if (rename(path, prev) != 0 && errno != ENOENT) return io_error(why, len, prev, "cannot keep the previous state");
  if (rename(tmp, path) != 0) return io_error(why, len, path, "cannot rename the new state into place");
  if (sync_directory(path) != 0) return io_error(why, len, path, "cannot sync its directory");
  return HM_OK;
}

/* The file's bytes (malloc'd into *bytes, *n of them); a verdict other than HM_STATE_RESTORED with the reason in
 * why when there is none to read. */
static hm_state_verdict read_file(const char *path, unsigned char **bytes, size_t *n, char *why, size_t len) {
  *bytes = NULL;
  *n = 0;
  const int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    snprintf(why, len, "%s", e == ENOENT ? "no file" : strerror(e));
    return e == ENOENT ? HM_STATE_NO_FILE : HM_STATE_UNREADABLE;
  }
  struct stat sb;
  hm_state_verdict v = HM_STATE_RESTORED;
  if (fstat(fd, &sb) != 0) {
    snprintf(why, len, "%s", strerror(errno));
    v = HM_STATE_UNREADABLE;
  } else if (sb.st_size > FILE_MAX_BYTES) {
    snprintf(why, len, "not a hunting_monitor state (%lld bytes)", (long long)sb.st_size);
    v = HM_STATE_NOT_A_STATE;
  } else if (!(*bytes = malloc(sb.st_size > 0 ? (size_t)sb.st_size : 1))) {
    snprintf(why, len, "out of memory");
    v = HM_STATE_UNREADABLE;
  }
  while (v == HM_STATE_RESTORED && *n < (size_t)sb.st_size) {
    const ssize_t k = read(fd, *bytes + *n, (size_t)sb.st_size - *n);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) {
      snprintf(why, len, "%s", strerror(errno));
      v = HM_STATE_UNREADABLE;
    }
    if (k <= 0) break; /* (shorter than its size said: the record's own checks see it) */
    *n += (size_t)k;
  }
  close(fd);
  if (v != HM_STATE_RESTORED) {
    free(*bytes);
    *bytes = NULL;
  }
  return v;
}

/* One file: read and restored, or why not (the reason without "not restored: " in why). */
static hm_status restore_one(hm_monitor m, const char *path, double now_s, double now_unix_s, hm_state_clock clock,
                             hm_state_outcome *o, char *why, size_t len) {
  unsigned char *bytes;
  size_t n;
  memset(o, 0, sizeof *o);
  o->verdict = read_file(path, &bytes, &n, why, len);
  if (o->verdict != HM_STATE_RESTORED) return HM_EIO;
  const hm_status st = hm_state_restore(m, bytes, n, now_s, now_unix_s, clock, o);
  free(bytes);
  const char *prefix = "not restored: ";
  say(why, len, "%s", strncmp(o->text, prefix, strlen(prefix)) == 0 ? o->text + strlen(prefix) : o->text);
  return st;
}

hm_status hm_state_restore_file(hm_monitor m, const char *path, double now_s, double now_unix_s, hm_state_clock clock,
                                hm_state_outcome *out) {
  hm_state_outcome o1, o2;
  char r1[HM_STATE_TEXT_MAX], r2[HM_STATE_TEXT_MAX], prev[PATH_BYTES];
  if (!m || !path || !out || !suffixed(path, ".prev", prev, sizeof prev)) return HM_EINVAL;
  const hm_status s1 = restore_one(m, path, now_s, now_unix_s, clock, &o1, r1, sizeof r1);
  if (s1 == HM_OK) {
    *out = o1;
    return HM_OK;
  }
  const hm_status s2 = restore_one(m, prev, now_s, now_unix_s, clock, &o2, r2, sizeof r2);
  if (s2 == HM_OK) {
    *out = o2;
    out->from_prev = 1;
    say(out->text, sizeof out->text, "restored from %s, %s (%s: %s)", prev, r2 + strlen("restored, "), path, r1);
    return HM_OK;
  }
  const int none = o1.verdict == HM_STATE_NO_FILE && o2.verdict == HM_STATE_NO_FILE;
  *out = o1.verdict == HM_STATE_NO_FILE ? o2 : o1;
  if (none) say(out->text, sizeof out->text, "not restored: no state file (%s)", path);
  else if (strcmp(r1, r2) == 0) say(out->text, sizeof out->text, "not restored: %s (and .prev): %s", path, r1);
  else say(out->text, sizeof out->text, "not restored: %s: %s; %s: %s", path, r1, prev, r2);
  return o1.verdict != HM_STATE_NO_FILE && o1.verdict != HM_STATE_UNREADABLE ? s1 : s2;
}
