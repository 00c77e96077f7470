/* For the C client tests: `mufric serve` in a child process on a free loopback port, and its end.
 * Header-only (static functions) so that each test program stays one source file. */
#ifndef MUFRIC_TESTS_SERVE_HELPER_H
#define MUFRIC_TESTS_SERVE_HELPER_H

#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char** environ;

/* Serves the models of directory `models` with the executable `mufric`; writes "host:port" into
 * address. Returns the server's pid, or -1 (with a message on stderr) if it did not come up in 30 s. */
static pid_t serve_models(const char* mufric, const char* models, char* address, size_t address_size) {
  char ready[64];
  snprintf(ready, sizeof ready, "/tmp/mufric_client_test_ready_%ld", (long)getpid());
  unlink(ready);
  char* argv[] = {(char*)mufric, "serve", "--models", (char*)models, "--listen", "127.0.0.1:0", "--ready-file", ready,
                  NULL};
  pid_t pid = -1;
  if (posix_spawn(&pid, mufric, NULL, NULL, argv, environ) != 0) {
    fprintf(stderr, "cannot start %s\n", mufric);
    return -1;
  }
  const struct timespec pause = {0, 20 * 1000 * 1000};
  for (int waited_ms = 0; waited_ms < 30000; waited_ms += 20) {
    FILE* file = fopen(ready, "r");
    if (file) {
      const int got = fgets(address, (int)address_size, file) != NULL;
      fclose(file);
      if (got) {
        address[strcspn(address, "\r\n")] = '\0';
        if (address[0] != '\0') {
          unlink(ready);
          return pid;
        }
      }
    }
    nanosleep(&pause, NULL);
  }
  fprintf(stderr, "mufric serve did not write %s within 30 s\n", ready);
  kill(pid, SIGTERM);
  waitpid(pid, NULL, 0);
  return -1;
}

static void stop_server(pid_t pid) {
  if (pid <= 0) return;
  kill(pid, SIGTERM);
  waitpid(pid, NULL, 0);
}

#endif
