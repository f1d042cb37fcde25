#pragma once
// core/mpi.hpp -- the MPI side of core::dispatch (core/dispatch.hpp): only in a program built
// with VRELAB_MPI (core/mpi.cpp is compiled into the program, never into the library, so the
// library and its users do not depend on MPI).
//
// start_mpi() initialises MPI when the process was launched by mpirun (Open MPI's, or a PMI
// launcher's, environment) and installs a Distributor for the job: rank 0 hands out item
// indices on request and takes every result (core/mpi.cpp's protocol, docs/mpi.md); the other
// ranks compute. Without mpirun it does nothing and returns nullptr: the program runs on
// threads as it always has. The returned object finalises MPI when destroyed.
#include <memory>

#include "core/dispatch.hpp"

namespace vrelab::core {

class MpiJob {
 public:
  virtual ~MpiJob() = default;
  // Ends the job from rank 0 after an error before every rank reached the same dispatch
  // (the others may be waiting for it): MPI_Abort with this exit code.
  virtual void abort(int code) = 0;
};

// True when the environment says mpirun (or another PMI launcher) started this process.
bool launched_by_mpirun();
std::unique_ptr<MpiJob> start_mpi(int* argc, char*** argv);

}  // namespace vrelab::core
