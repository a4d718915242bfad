/* src/scene/scene_file.c — reading a scene's bytes: a regular file, or standard input for
 * the path "-", never more than SC_MAX_BYTES.
 * SPDX-License-Identifier: MIT
 *
 * A scene path that names a device (/dev/zero, /dev/stdin on a terminal), a FIFO or a
 * directory is refused before reading: such a "file" may never end or block forever. The
 * path "-" is the one way to pipe a scene in (messages then name it "<stdin>"). A file
 * larger than the cap is refused as soon as the cap is passed, so nothing larger is ever
 * held in memory.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene/scene_internal.h"

#define STDIN_NAME "<stdin>"

static const char *kind_of(mode_t m) {
  return S_ISDIR(m)    ? "a directory"
         : S_ISCHR(m)  ? "a character device"
         : S_ISBLK(m)  ? "a block device"
         : S_ISFIFO(m) ? "a FIFO (named pipe)"
         : S_ISSOCK(m) ? "a socket"
                       : "not a regular file";
}

/* Read all of fd, at most SC_MAX_BYTES. Returns a malloc'd buffer (*len bytes) or NULL
 * with a message. */
static char *read_all(int fd, const char *name, size_t *len, char *err, size_t errlen) {
  size_t cap = 4096, n = 0;
  char *buf = cv_malloc(cap);
  /* one byte more than the cap is read, to tell "exactly the cap" from "more" */
  while (buf && n <= SC_MAX_BYTES) {
    if (n == cap) {
      size_t ncap = cap * 2 > (size_t)SC_MAX_BYTES + 1 ? (size_t)SC_MAX_BYTES + 1 : cap * 2;
      char *nb = cv_realloc(buf, ncap);
      if (!nb) cv_free(buf);
      buf = nb;
      cap = ncap;
      continue;
    }
    ssize_t k = read(fd, buf + n, cap - n);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) {
      int e = errno;
      cv_free(buf);
      sc_err(err, errlen, name, 0, "read error: %s", strerror(e));
      return NULL;
    }
    if (k == 0) break;
    n += (size_t)k;
  }
  if (!buf) {
    sc_err(err, errlen, name, 0, "out of memory");
    return NULL;
  }
  if (n > SC_MAX_BYTES) {
    cv_free(buf);
    sc_err(err, errlen, name, 0,
           "the scene is larger than %d bytes (%d MiB), the most "
           "calcvar reads; is this a scene file?",
           SC_MAX_BYTES, SC_MAX_BYTES >> 20);
    return NULL;
  }
  *len = n;
  return buf;
}

static scene *load_file(const char *path, int nset, const sc_set *set, int inputs, char *err,
                        size_t errlen) {
  scene *(*from_buffer)(const char *, size_t, const char *, int, const sc_set *, char *, size_t) =
      inputs ? scene_load_buffer_inputs : scene_load_buffer;
  if (err && errlen) err[0] = '\0';
  size_t len = 0;
  char *buf;
  const char *name = path;
  if (strcmp(path, "-") == 0) {
    /* Standard input can be read once: its text is kept for later loads of "-" in the same
     * process (`solve - --continue` reloads the scene at every step). */
    static char *stdin_text;
    static size_t stdin_len;
    name = STDIN_NAME;
    if (!stdin_text && !(stdin_text = read_all(STDIN_FILENO, name, &stdin_len, err, errlen)))
      return NULL;
    return from_buffer(stdin_text, stdin_len, name, nset, set, err, errlen);
  } else {
    /* Refuse what is not a regular file before opening it: opening a FIFO blocks. */
    struct stat st;
    if (stat(path, &st) != 0) {
      sc_err(err, errlen, path, 0, "cannot open: %s", strerror(errno));
      return NULL;
    }
    if (!S_ISREG(st.st_mode)) {
      sc_err(err, errlen, path, 0,
             "cannot read a scene from %s; give a scene file, or '-' "
             "for standard input",
             kind_of(st.st_mode));
      return NULL;
    }
    int fd = open(path, O_RDONLY | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
      sc_err(err, errlen, path, 0, "cannot open: %s", strerror(errno));
      return NULL;
    }
    /* the path may have been replaced between stat and open: check what was opened */
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      close(fd);
      sc_err(err, errlen, path, 0,
             "cannot read a scene from %s; give a scene file, or '-' "
             "for standard input",
             kind_of(st.st_mode));
      return NULL;
    }
    buf = read_all(fd, path, &len, err, errlen);
    close(fd);
  }
  if (!buf) return NULL;
  scene *s = from_buffer(buf, len, name, nset, set, err, errlen);
  cv_free(buf);
  return s;
}

scene *scene_load_file(const char *path, int nset, const sc_set *set, char *err, size_t errlen) {
  return load_file(path, nset, set, 0, err, errlen);
}

scene *scene_load_file_inputs(const char *path, int nset, const sc_set *set, char *err,
                              size_t errlen) {
  return load_file(path, nset, set, 1, err, errlen);
}
