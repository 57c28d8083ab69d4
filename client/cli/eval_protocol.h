// `sfcsampler eval`'s protocol section: the paper's discrepancy protocol
// (Tables 1-2) with our point sets from a SampleSource (a server's travel,
// made from the same trees; in process RunProtocol makes them itself), and
// the reference sets and the discrepancies computed here. The slope tables go to
// stdout; discrepancy.csv, slopes.md and the plots (svg, png) into a folder.
// Thread-safety: call from one thread.
#ifndef SFCSAMPLER_CLIENT_CLI_EVAL_PROTOCOL_H_
#define SFCSAMPLER_CLIENT_CLI_EVAL_PROTOCOL_H_

#include <string>

#include "client/cli/sample_source.h"
#include "evaluation/protocol.h"

namespace sfc {

// Runs the protocol of `options` and writes its files into `out_dir`, with
// our sets from `server` (its our_sets set here) or, when it is null, made
// in process by RunProtocol itself. Returns the process exit code.
int RunEvalProtocol(ProtocolOptions options, const std::string& out_dir, SampleSource* server);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_EVAL_PROTOCOL_H_
