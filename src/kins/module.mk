# sources of src/kins (C++17 and Eigen behind include/ncpar/kins.h)
LIB_CXXSRCS += $(wildcard src/kins/*.cpp)
