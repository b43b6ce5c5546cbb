# The sources that repeat numpy's or Eigen's arithmetic operation by operation (README.md beside
# this file): compiled without fused multiply-adds, whatever -march a build is given, so that
# each product is rounded before it is added, as numpy and Eigen round it.
set(WIRESCULPT_EXACT_SOURCES ${CMAKE_CURRENT_LIST_DIR}/../target_placement.cpp)
set_source_files_properties(${WIRESCULPT_EXACT_SOURCES} PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
