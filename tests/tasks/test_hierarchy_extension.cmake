# Two Controllers in one TU: -O1 halves the compile time; the test solves a handful of QPs.
target_compile_options(${name} PRIVATE -O1)
