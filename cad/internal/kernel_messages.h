// Internal to cad/: keeps OpenCASCADE from printing to stdout. The kernel's
// readers and writers report through its default messenger, whose printer
// writes to std::cout; the server and the CLI own their output, and cad/
// reports through absl::Status. Thread-safe (runs once per process).
#ifndef SFCSAMPLER_CAD_INTERNAL_KERNEL_MESSAGES_H_
#define SFCSAMPLER_CAD_INTERNAL_KERNEL_MESSAGES_H_

namespace sfc::cad {

// Removes every printer from the kernel's default messenger, once.
void SilenceKernelMessages();

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_KERNEL_MESSAGES_H_
