/* Runs a harness's LLVMFuzzerTestOneInput once per file named on the
 * command line, without libFuzzer: lets gcc's sanitizers (tests/sanitize.sh)
 * replay the seed corpus and the crash regressions where clang's fuzzer
 * runtime is not installed. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
  for (int i = 1; i < argc; i++) {
    FILE *f = fopen(argv[i], "rb");
    if (!f) {
      fprintf(stderr, "replay: %s: cannot open\n", argv[i]);
      return 2;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
      if (!buf) {
        fprintf(stderr, "replay: out of memory\n");
        return 2;
      }
      n += fread(buf + n, 1, cap - n, f);
      if (n < cap) break;
      cap *= 2;
      uint8_t *bigger = realloc(buf, cap);
      if (!bigger) free(buf);
      buf = bigger;
    }
    fclose(f);
    /* Exact-size copy: reading past the input must be caught by ASan. */
    uint8_t *exact = malloc(n ? n : 1);
    if (!exact) return 2;
    for (size_t k = 0; k < n; k++) exact[k] = buf[k];
    free(buf);
    LLVMFuzzerTestOneInput(exact, n);
    free(exact);
  }
  printf("replay: %d input(s) ok\n", argc - 1);
  return 0;
}
