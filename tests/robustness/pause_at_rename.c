/* Test helper, preloaded into a tool (LD_PRELOAD) by atomic_write_test: the tool stops for good
 * at the rename() that would move a finished temporary file "<name>.tmp.<pid>" into place, after
 * writing one byte to the file descriptor JVL_PAUSE_FD. The test then signals the tool at a known
 * point inside its write instead of racing it. JVL_PAUSE_MATCH, if set, limits this to renames
 * whose target contains that text. Without JVL_PAUSE_FD every rename passes through. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int rename(const char* from, const char* to) {
  static int (*real_rename)(const char*, const char*) = NULL;
  if (real_rename == NULL) real_rename = (int (*)(const char*, const char*))dlsym(RTLD_NEXT, "rename");
  const char* fd = getenv("JVL_PAUSE_FD");
  const char* match = getenv("JVL_PAUSE_MATCH");
  if (fd != NULL && strstr(from, ".tmp.") != NULL && (match == NULL || strstr(to, match) != NULL)) {
    const char byte = 'p';
    if (write(atoi(fd), &byte, 1) != 1) _exit(125);
    for (;;) pause();
  }
  return real_rename(from, to);
}
