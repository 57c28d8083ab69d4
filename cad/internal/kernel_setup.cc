#include "cad/internal/kernel_setup.h"

#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <OSD.hxx>
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

void ConvertKernelSignals() {
  static std::once_flag once;
  // No floating-point traps: evaluation may produce NaN, which callers check.
  std::call_once(once, [] { OSD::SetSignal(OSD_SignalMode_SetUnhandled, false); });
}

}  // namespace sfc::cad
