#include <bodyfit/app/huge_page_heap.hpp>

#include <malloc.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <unistd.h>

namespace bodyfit {

void restart_on_huge_pages(char** argv) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string before = tunables ? tunables : "";
  if (before.find("glibc.malloc.hugetlb") != std::string::npos) return;
  std::string mode;
  std::getline(std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"), mode);
  if (mode.find("[never]") != std::string::npos || mode.empty()) return;
  const std::string after = before.empty() ? "glibc.malloc.hugetlb=1" : before + ":glibc.malloc.hugetlb=1";
  if (::setenv("GLIBC_TUNABLES", after.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  // Still here (no /proc): the ordinary heap, and the environment as it was.
  if (tunables) ::setenv("GLIBC_TUNABLES", before.c_str(), 1);
  else ::unsetenv("GLIBC_TUNABLES");
}

bool heap_on_huge_pages() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return tunables && std::string(tunables).find("glibc.malloc.hugetlb=1") != std::string::npos;
}

void keep_freed_blocks() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

}  // namespace bodyfit
