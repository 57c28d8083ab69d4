// A tree's summary (request/tree_summary.h) as the dict Python hands over:
// the wire's TreeInfo names, in its order, every key for every kind. Both
// extensions use it, the embedded sampler (sampling.cc) and the client
// (client.cc), so Samples.tree reads the same in process and from a server.
// REQUIRES the GIL.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_TREE_SUMMARY_DICT_H_
#define SFCSAMPLER_PYTHON_BINDINGS_TREE_SUMMARY_DICT_H_

#include "pybind11/pybind11.h"
#include "request/tree_summary.h"

namespace sfc::python {

pybind11::dict TreeSummaryDict(const TreeSummary& summary);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_TREE_SUMMARY_DICT_H_
