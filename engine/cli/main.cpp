// Placeholder until the command line lands (issue 2, item 4).
#include <cstdio>

int main() {
  std::fprintf(stderr, "odemag: not implemented yet\n");
  return 1;
}
