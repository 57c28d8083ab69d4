#include "cad/internal/kernel_setup.h"

#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <OSD.hxx>
#include <OSD_SIGBUS.hxx>
#include <OSD_SIGSEGV.hxx>
#include <Standard_Failure.hxx>
#include <signal.h>

#include <memory>
#include <mutex>

namespace sfc::cad {

void SilenceKernelMessages() {
  static std::once_flag once;
  std::call_once(once, [] {
    const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
    const Message_SequenceOfPrinters printers = messenger->Printers();
    for (Message_SequenceOfPrinters::Iterator it(printers); it.More(); it.Next()) {
      messenger->RemovePrinter(it.Value());
    }
  });
}

namespace {

// This thread's alternate signal stack, removed when the thread ends.
class AltStack {
 public:
  AltStack() : memory_(new char[kBytes]) {
    stack_t stack{};
    stack.ss_sp = memory_.get();
    stack.ss_size = kBytes;
    installed_ = sigaltstack(&stack, nullptr) == 0;
  }
  ~AltStack() {
    if (!installed_) return;
    stack_t off{};
    off.ss_flags = SS_DISABLE;
    sigaltstack(&off, nullptr);
  }
  AltStack(const AltStack&) = delete;
  AltStack& operator=(const AltStack&) = delete;

 private:
  static constexpr size_t kBytes = size_t{256} << 10;
  std::unique_ptr<char[]> memory_;
  bool installed_ = false;
};

}  // namespace

void ConvertKernelSignals() {
  static std::once_flag once;
  std::call_once(once, [] {
    // The type descriptors a converted fault needs, made now: made first
    // inside a fault's handling, a second fault there leaves the static's
    // guard taken, and every later fault waits on it for good (iges_fuzzer
    // met it, in __cxa_guard_acquire for type_instance<Standard_Failure>).
    (void)STANDARD_TYPE(Standard_Failure);
    (void)STANDARD_TYPE(OSD_SIGSEGV);
    (void)STANDARD_TYPE(OSD_SIGBUS);
    // No floating-point traps: evaluation may produce NaN, which callers check.
    OSD::SetSignal(OSD_SignalMode_SetUnhandled, false);
    // A stack overflow (the kernel recursing through a cycle of references)
    // faults where no stack is left to run a handler on: the handlers run on
    // each thread's alternate stack instead.
    for (int signal : {SIGSEGV, SIGBUS}) {
      struct sigaction action {};
      if (sigaction(signal, nullptr, &action) != 0) continue;
      if (action.sa_handler == SIG_DFL || action.sa_handler == SIG_IGN) continue;
      action.sa_flags |= SA_ONSTACK;
      sigaction(signal, &action, nullptr);
    }
  });
  thread_local AltStack alt_stack;
}

}  // namespace sfc::cad
