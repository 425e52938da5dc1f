# -O1: the test solves a handful of QPs; optimizing harder only costs compile time (the TU holds
# a Controller and a bare HqpWbc, ~3.5 CPU min).
target_compile_options(${name} PRIVATE -O1)
