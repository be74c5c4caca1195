// Placeholder until the file is written; see rcm/CMakeLists.txt.
