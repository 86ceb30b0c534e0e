# Every dependency comes from Debian's packages (scripts/install-deps.sh installs them).
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(ZLIB REQUIRED)
find_package(Boost 1.74 REQUIRED)
find_package(PkgConfig REQUIRED)

# SuiteSparse CHOLMOD (peer solver): Debian ships plain headers and libraries, no CMake config.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
add_library(cleave_cholmod INTERFACE)
target_include_directories(cleave_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(cleave_cholmod INTERFACE ${CHOLMOD_LIBRARY})

# teem (NRRD reading), nifticlib (NIfTI-1/2), assimp (OBJ/STL/PLY/OFF), OpenVDB (robust voxelization).
find_path(TEEM_INCLUDE_DIR teem/nrrd.h REQUIRED)
find_library(TEEM_LIBRARY teem REQUIRED)
add_library(cleave_teem INTERFACE)
target_include_directories(cleave_teem SYSTEM INTERFACE ${TEEM_INCLUDE_DIR})
target_link_libraries(cleave_teem INTERFACE ${TEEM_LIBRARY})

find_path(NIFTI_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti REQUIRED)
find_library(NIFTI2_LIBRARY NAMES nifti2 REQUIRED)
find_library(ZNZ_LIBRARY znz REQUIRED)
add_library(cleave_nifti INTERFACE)
target_include_directories(cleave_nifti SYSTEM INTERFACE ${NIFTI_INCLUDE_DIR})
target_link_libraries(cleave_nifti INTERFACE ${NIFTI2_LIBRARY} ${ZNZ_LIBRARY} ZLIB::ZLIB m)

find_package(assimp REQUIRED)
list(APPEND CMAKE_MODULE_PATH "/usr/lib/x86_64-linux-gnu/cmake/OpenVDB" "/usr/lib/cmake/OpenVDB")
find_path(OPENVDB_INCLUDE_DIR openvdb/openvdb.h REQUIRED)
find_library(OPENVDB_LIBRARY openvdb REQUIRED)
add_library(cleave_openvdb INTERFACE)
target_include_directories(cleave_openvdb SYSTEM INTERFACE ${OPENVDB_INCLUDE_DIR})
# OpenVDB's headers use Imath's half tables; link Imath explicitly (clang at -O1 does not inline them).
find_package(Imath CONFIG REQUIRED)
target_link_libraries(cleave_openvdb INTERFACE ${OPENVDB_LIBRARY} Imath::Imath TBB::tbb)
