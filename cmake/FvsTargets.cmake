# Small helpers so that every folder declares its library and tests the same way.

function(fvs_add_subdirectory_if_present DIR)
  if(EXISTS ${CMAKE_SOURCE_DIR}/${DIR}/CMakeLists.txt)
    add_subdirectory(${CMAKE_SOURCE_DIR}/${DIR})
  endif()
endfunction()

# fvs_add_library(NAME SRCS a.cc b.cc DEPS lib1 lib2 [PRIVATE_DEPS ...] [TORCH])
# TORCH: the library's sources include torch/torch.h; they reuse one precompiled header.
function(fvs_add_library NAME)
  cmake_parse_arguments(L "TORCH" "" "SRCS;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${NAME} STATIC ${L_SRCS})
  target_include_directories(${NAME} PUBLIC ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR})
  target_link_libraries(${NAME} PUBLIC ${L_DEPS} PRIVATE ${L_PRIVATE_DEPS})
  if(L_TORCH)
    fvs_use_torch_pch(${NAME})
  endif()
endfunction()

# One precompiled torch/torch.h shared by every LibTorch translation unit: torch/torch.h is
# most of such a file's compile time (doc/design.md has the figures).
function(fvs_use_torch_pch TARGET)
  if(NOT TARGET fvs_torch_pch)
    file(WRITE ${CMAKE_BINARY_DIR}/fvs_torch_pch.cc "// precompiled-header anchor\n")
    add_library(fvs_torch_pch STATIC ${CMAKE_BINARY_DIR}/fvs_torch_pch.cc)
    target_link_libraries(fvs_torch_pch PUBLIC ${TORCH_LIBRARIES})
    target_precompile_headers(fvs_torch_pch PRIVATE <torch/torch.h>)
  endif()
  target_link_libraries(${TARGET} PUBLIC ${TORCH_LIBRARIES})
  target_precompile_headers(${TARGET} REUSE_FROM fvs_torch_pch)
endfunction()

# fvs_add_test(NAME SRCS a_test.cc DEPS lib [TORCH] [XVFB] [LABELS l1 l2] [TIMEOUT s])
# XVFB: the test opens windows with OpenGL; it runs under xvfb-run (Mesa's llvmpipe gives
# real GL there; Qt's offscreen platform has none) with QT_QPA_PLATFORM=xcb.
# One executable and one ctest entry per test file group: a binary linking OIIO loads OpenCV
# at start-up (doc/design.md), so a process per GoogleTest case would waste minutes.
function(fvs_add_test NAME)
  cmake_parse_arguments(T "TORCH;XVFB" "TIMEOUT" "SRCS;DEPS;LABELS" ${ARGN})
  add_executable(${NAME} ${T_SRCS})
  set_target_properties(${NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  target_link_libraries(${NAME} PRIVATE ${T_DEPS} GTest::gtest GTest::gtest_main Threads::Threads)
  target_include_directories(${NAME} PRIVATE ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR} ${CMAKE_SOURCE_DIR}/tests)
  if(T_TORCH)
    fvs_use_torch_pch(${NAME})
  endif()
  set(qpa offscreen)
  if(T_XVFB)
    find_program(FVS_XVFB_RUN xvfb-run)
    if(NOT FVS_XVFB_RUN)
      message(WARNING "xvfb-run not found: ${NAME} needs an X display (DISPLAY) to pass")
    endif()
    set(qpa xcb)
  endif()
  if(T_XVFB AND FVS_XVFB_RUN)
    add_test(NAME ${NAME} COMMAND ${FVS_XVFB_RUN} -a -s "-screen 0 1280x1024x24"
             $<TARGET_FILE:${NAME}> --gtest_brief=1)
    # xvfb-run -a picks a free display number, racily: one X test at a time.
    set_tests_properties(${NAME} PROPERTIES RESOURCE_LOCK xvfb)
  else()
    add_test(NAME ${NAME} COMMAND ${NAME} --gtest_brief=1)
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  if(FVS_SANITIZE)
    # Instrumented code runs 2-3x slower (scripts/sanitize.sh).
    math(EXPR T_TIMEOUT "${T_TIMEOUT} * 3")
  endif()
  set(env "QT_QPA_PLATFORM=${qpa};FVS_SOURCE_DIR=${CMAKE_SOURCE_DIR};FVS_BINARY_DIR=${CMAKE_BINARY_DIR}")
  if(FVS_SANITIZE)
    list(APPEND env "LSAN_OPTIONS=suppressions=${CMAKE_SOURCE_DIR}/tests/lsan.supp")
  endif()
  set_tests_properties(${NAME} PROPERTIES TIMEOUT ${T_TIMEOUT} ENVIRONMENT "${env}")
  if(FVS_SANITIZE AND T_XVFB)
    # Mesa's llvmpipe registers its JIT code's unwind tables under libgcc's lock, and a
    # malloc there unwinds again under ASan's slow unwinder (fast_unwind_on_malloc=0,
    # scripts/sanitize.sh): main_window_test deadlocked in _Unwind_Find_FDE. softpipe
    # renders the same GL without a JIT, and the slow unwinder then sees whole stacks,
    # which tests/lsan.supp needs to name the system libraries' leaks.
    set_tests_properties(${NAME} PROPERTIES ENVIRONMENT_MODIFICATION
                         "GALLIUM_DRIVER=set:softpipe")
  endif()
  if(T_LABELS)
    set_tests_properties(${NAME} PROPERTIES LABELS "${T_LABELS}")
  endif()
endfunction()

# fvs_add_folder_library(NAME DEPS ... [TORCH]): a library from every *.cc of the calling
# folder (tests live in tests/<folder>/), so adding a file needs no CMake edit.
function(fvs_add_folder_library NAME)
  cmake_parse_arguments(L "TORCH" "" "DEPS;PRIVATE_DEPS;EXCLUDE" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  foreach(ex ${L_EXCLUDE})
    list(FILTER srcs EXCLUDE REGEX "/${ex}$")
  endforeach()
  if(NOT srcs)
    # A folder with headers only (or not written yet): an interface library keeps the
    # dependency graph intact.
    add_library(${NAME} INTERFACE)
    target_include_directories(${NAME} INTERFACE ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR})
    target_link_libraries(${NAME} INTERFACE ${L_DEPS})
    return()
  endif()
  if(L_TORCH)
    fvs_add_library(${NAME} SRCS ${srcs} DEPS ${L_DEPS} PRIVATE_DEPS ${L_PRIVATE_DEPS} TORCH)
  else()
    fvs_add_library(${NAME} SRCS ${srcs} DEPS ${L_DEPS} PRIVATE_DEPS ${L_PRIVATE_DEPS})
  endif()
endfunction()
