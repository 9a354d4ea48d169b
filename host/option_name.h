// An option that a command and run.yaml share, named once: its run.yaml key, its command-line flag and its
// one-line help. Each command's table (host/train/train_option_names.h, ...) holds these; the CLI in tools/
// declares its flags from them, run.yaml (host/run/run_config.h) documents its keys with them, and run's
// stages turn a section's keys into the child command's flags with them, so that a name or a help line is
// written in one place.
#pragma once

namespace litgs::host {

struct OptionName {
  const char* key;   // run.yaml key in the command's section
  const char* flag;  // CLI11 name: "--iterations"; a bool that turns something off: "!--no-clahe"
  const char* help;  // one line
};

}  // namespace litgs::host
