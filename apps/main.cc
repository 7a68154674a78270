#include <malloc.h>

#include "apps/commands.h"

int main(int argc, char** argv) {
  // glibc serves large blocks (the models' tensors, decoded images) with mmap and
  // returns them at free, so every inference page-faults and zeroes its buffers afresh:
  // on the development recording a detector + fit-only job spent a third of its time in
  // the kernel (46.9 s; 17.8 s with these settings, the same peak memory). Keep freed
  // memory in the process for the next frame instead.
  mallopt(M_MMAP_THRESHOLD, 512 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  return handlabel::RunHandlabel(argc, argv);
}
