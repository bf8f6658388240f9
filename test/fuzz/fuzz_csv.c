/* libFuzzer harness: the command-line tool's CSV reader (the files `hunting estimate` and `fit-conicity` read). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "cli.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static char path[64];
  if (!path[0]) snprintf(path, sizeof path, "/tmp/hm_fuzz_csv_%d.csv", (int)getpid());
  FILE *f = fopen(path, "wb");
  if (!f) return 0;
  fwrite(data, 1, size, f);
  fclose(f);
  for (int ncols = 1; ncols <= 3; ++ncols) {
    char header[3][64];
    double *d = NULL;
    size_t n = 0;
    if (cli_read_csv(path, ncols, header, &d, &n, ncols == 2) == 0) free(d);
  }
  return 0;
}
