/* Opens a shipped model by name through the installed libmufric.so and prints mu at one point:
 * which file the name reached is then told by its mu. Usage: shipped_model NAME */
#include <stdio.h>

#include <mufric/mufric.h>

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  mufric_client* client = NULL;
  if (mufric_open(argv[1], &client) != MUFRIC_OK) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 1;
  }
  const double p = 800e6, v = 1.0, t = 773.15;
  double mu = 0.0;
  const int code = mufric_evaluate(client, 1, &p, &v, &t, NULL, 0.0, &mu, NULL, NULL, NULL, NULL);
  mufric_close(client);
  if (code != MUFRIC_OK) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 1;
  }
  printf("%.6f\n", mu);
  return 0;
}
