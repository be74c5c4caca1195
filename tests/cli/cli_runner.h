// Runs a program of the build as a user would and captures what it prints.
#ifndef RCM_TESTS_CLI_CLI_RUNNER_H_
#define RCM_TESTS_CLI_CLI_RUNNER_H_

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_file.h"

namespace rcm::test {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string ReadWholeFile(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream contents;
  contents << stream.rdbuf();
  return contents.str();
}

// Quotes an argument for /bin/sh.
inline std::string ShellQuote(const std::string& arg) {
  std::string quoted = "'";
  for (char c : arg) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// `program` with `args` (already split), stdout and stderr captured.
inline RunResult RunProgram(const std::string& program,
                            const std::vector<std::string>& args) {
  const std::string base = TempFilePath("run");
  std::string command = ShellQuote(program);
  for (const std::string& arg : args) command += " " + ShellQuote(arg);
  command +=
      " >" + ShellQuote(base + ".out") + " 2>" + ShellQuote(base + ".err");
  const int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadWholeFile(base + ".out");
  result.err = ReadWholeFile(base + ".err");
  return result;
}

// True when `text` is exactly one non-empty line.
inline bool IsOneLine(const std::string& text) {
  return text.size() > 1 && text.back() == '\n' &&
         text.find('\n') == text.size() - 1;
}

}  // namespace rcm::test

#endif  // RCM_TESTS_CLI_CLI_RUNNER_H_
