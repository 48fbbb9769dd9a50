# FVS_FUZZ=ON (doc/reliability.md, "Fuzzing"): builds only the libFuzzer targets of
# tests/fuzz/ and the torch-free libraries whose readers they call, with clang, ASan and
# UBSan. LibTorch, COLMAP, Qt and the test suite are not needed: none of the parsers of
# user files needs them, and a full sanitized build would take hours on 2 cores.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "FVS_FUZZ needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++")
endif()

# fuzzer-no-link: the libraries get the coverage instrumentation, only the targets link
# libFuzzer's main. No recovery: UBSan findings stop the run as ASan's do.
add_compile_options(-g -fno-omit-frame-pointer
                    -fsanitize=fuzzer-no-link,address,undefined
                    -fno-sanitize-recover=all)
add_link_options(-fsanitize=address,undefined)
add_compile_options(-Wall -Wextra -Wno-unused-parameter -Wno-sign-compare)

find_package(Threads REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(PkgConfig REQUIRED)
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
find_package(SQLite3 REQUIRED)

fvs_add_subdirectory_if_present(src/fvs/util)
fvs_add_subdirectory_if_present(src/fvs/geometry)
fvs_add_subdirectory_if_present(colmap_ext)
fvs_add_subdirectory_if_present(src/fvs/scene)

# Readers that live in LibTorch or Ceres libraries but do not use them themselves: their
# files alone (render/targets.cc, path/camera_path_io.cc and the others include no
# torch header).
add_library(fvs_fuzz_readers STATIC
  ${CMAKE_SOURCE_DIR}/src/fvs/render/targets.cc
  ${CMAKE_SOURCE_DIR}/src/fvs/path/camera_path_io.cc
  ${CMAKE_SOURCE_DIR}/src/fvs/net/model_config.cc
  ${CMAKE_SOURCE_DIR}/src/fvs/mvs/stereo_config.cc)
target_include_directories(fvs_fuzz_readers PUBLIC ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR})
target_link_libraries(fvs_fuzz_readers PUBLIC fvs_scene fvs_colmap_ext fvs_geometry fvs_util)

enable_testing()
add_subdirectory(${CMAKE_SOURCE_DIR}/tests/fuzz)
