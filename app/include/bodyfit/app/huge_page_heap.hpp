#pragma once
// The heap of bodyfit's processes: one-shot processes on transparent huge pages, freed blocks kept.
//
// A process's fresh memory costs a page fault per 4 KiB page at its first write. On the virtual
// machines bodyfit is measured on a fault costs ~14 µs, so a stage command (read a mesh, one stage,
// write the result) spent more time faulting in its new arrays than filling them. glibc backs its
// heap with 2 MiB pages when the tunable glibc.malloc.hugetlb=1 is set, which it reads only at a
// process's start: a one-shot command therefore starts itself again with it, once. Not `run`: its
// iterations reuse the heap they grew, and on huge pages they were not faster
// (docs/validation/performance.md).

namespace bodyfit {

/// Replaces this process by the same program with the same arguments and glibc's heap on huge
/// pages, unless GLIBC_TUNABLES already names glibc.malloc.hugetlb (the restarted process, or a
/// user's choice: `GLIBC_TUNABLES=glibc.malloc.hugetlb=0` keeps the ordinary heap) or the system
/// has transparent huge pages off. Returns, changing nothing, when it does not restart.
void restart_on_huge_pages(char** argv);

/// Whether this process started with glibc.malloc.hugetlb=1.
bool heap_on_huge_pages();

/// Keeps freed blocks up to 256 MiB in the heap instead of unmapping them, as `bodyfit` does from
/// its start: every stage allocates arrays of 10-130 MB at a million faces, and glibc's default
/// maps and unmaps each one, so every reuse pays its page faults again (a third of the CPU time was
/// system time). Peak memory grows by about a fifth (docs/validation/performance.md).
void keep_freed_blocks();

}  // namespace bodyfit
