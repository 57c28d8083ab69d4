// Internal to cad/: process-wide set-up of OpenCASCADE, done once.
//
// Messages: the kernel's readers and writers report through its default
// messenger, whose printer writes to std::cout; the server and the CLI own
// their output, and cad/ reports through absl::Status.
//
// Signals: on malformed input the kernel can dereference a null pointer (a
// mangled IGES file crashes IGESSolid_Face::NbLoops in 7.6). OSD::SetSignal
// installs handlers that, inside a block guarded by OCC_CATCH_SIGNALS (Debian
// builds OpenCASCADE with OCC_CONVERT_SIGNALS), jump back to that block and
// throw a Standard_Failure. The handlers are installed only for signals that
// have no handler yet (OSD_SignalMode_SetUnhandled), so a handler the program
// set first is kept, and then such crashes stay crashes. The handlers run on
// an alternate signal stack, which ConvertKernelSignals gives the calling
// thread: a stack overflow inside the kernel (an ORIENTED_EDGE whose edge is
// itself makes StepShape_OrientedEdge::EdgeStart recurse forever, found by
// fuzz/step_fuzzer) becomes a Standard_Failure too.
//
// Thread-safety: both functions are thread-safe and idempotent.
#ifndef SFCSAMPLER_CAD_INTERNAL_KERNEL_SETUP_H_
#define SFCSAMPLER_CAD_INTERNAL_KERNEL_SETUP_H_

namespace sfc::cad {

// Removes every printer from the kernel's default messenger, once.
void SilenceKernelMessages();

// Installs the kernel's signal handlers where none is set, once, and gives
// the calling thread an alternate signal stack (once per thread).
void ConvertKernelSignals();

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_KERNEL_SETUP_H_
