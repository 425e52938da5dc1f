#pragma once
// Recording the balance controller's HQP problem instances during a run (docs/recording.md):
// the driver copies each recorded tick's problem into a buffer allocated here, before the run,
// and the file is written after it. Not real-time code (allocates, throws).

#include <cstddef>
#include <string>

#include "run.hpp"

namespace hqp::sim {

struct RecordOptions {
  std::string file;       // written by finishRecording()
  double start = 0.0;     // s, first recorded tick (run time)
  double duration = 2.0;  // s, length of the recorded window
  int every = 1;          // keep every Nth tick of the window
  std::string source;     // free text stored in the file (scenario, command line)
};

// From the driver's next run on, records the ticks of the window. False (nothing recorded)
// for drivers without an HQP: the joint-PD stand-in, WQP, builds without the controller.
bool startRecording(Driver& driver, const RecordOptions& options);

// After the run: writes the instances of the last run to options.file and returns their
// number. Throws std::runtime_error (hqp::ProblemFileError) if the file cannot be written.
std::size_t finishRecording(Driver& driver);

}  // namespace hqp::sim
