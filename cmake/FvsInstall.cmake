# Install rules and the Debian package (doc/install.md).
#
# Layout under the prefix P (`cmake --install build --prefix P`):
#   bin/colmap-fvs                  the front door (build/bin/colmap)
#   bin/colmap -> colmap-fvs        component colmap_name: one `colmap` on the PATH runs ours and
#   bin/.fvs_front_door               execs the real COLMAP for the rest (the marker keeps the
#                                     runner from taking this link for the real COLMAP)
#   bin/fvs_train_main              the standalone trainer
#   lib/colmap-fvs/bin/colmap       a link to ../../../bin/colmap-fvs with a marker beside it:
#                                     put this folder first on the PATH to get `colmap` from
#                                     the .deb, which leaves /usr/bin/colmap to Debian's COLMAP
#   share/colmap-fvs/models/        the shipped weights and their JSON cards (ShippedModelPath
#                                     looks in <exe>/../share/colmap-fvs/models)
#   share/doc/colmap-fvs/           README.md, doc/
#   share/man/man1/colmap-fvs.1     the manual page
# The .deb (cpack -G DEB, prefix /usr) holds everything but component colmap_name, so it never
# touches /usr/bin/colmap.
include(GNUInstallDirs)

set(FVS_INSTALL_SHARE_DIR ${CMAKE_INSTALL_DATADIR}/colmap-fvs)
set(FVS_INSTALL_DOC_DIR ${CMAKE_INSTALL_DATADIR}/doc/colmap-fvs)

# Build-tree binaries find the source tree's models/ the way installed ones find theirs:
# build/bin/../share/colmap-fvs/models is a link to it (no source path is compiled in).
set(fvs_models_link ${CMAKE_BINARY_DIR}/share/colmap-fvs/models)
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/share/colmap-fvs)
set(fvs_models_target "")
if(IS_SYMLINK ${fvs_models_link})
  file(READ_SYMLINK ${fvs_models_link} fvs_models_target)
endif()
if(NOT fvs_models_target STREQUAL "${CMAKE_SOURCE_DIR}/models")
  file(REMOVE ${fvs_models_link})
  file(CREATE_LINK ${CMAKE_SOURCE_DIR}/models ${fvs_models_link} SYMBOLIC)
endif()

# Paths as seen by the install script: DESTDIR (set by CPack) + the prefix.
set(fvs_dest_bin "\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}")
set(fvs_dest_wrapper "\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/lib/colmap-fvs/bin")

if(TARGET colmap)
  # install(TARGETS) rewrites the RPATH (none is kept: CMAKE_INSTALL_RPATH is empty) but
  # cannot rename; the binary is installed as bin/colmap and renamed. A bin/colmap link
  # left by an earlier install is removed first, else the copy would go through it.
  install(CODE "
    if(IS_SYMLINK \"${fvs_dest_bin}/colmap\")
      file(REMOVE \"${fvs_dest_bin}/colmap\")
    endif()" COMPONENT runtime)
  install(TARGETS colmap RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  install(CODE "
    file(RENAME \"${fvs_dest_bin}/colmap\" \"${fvs_dest_bin}/colmap-fvs\")
    message(STATUS \"Renamed to: ${fvs_dest_bin}/colmap-fvs\")
    file(MAKE_DIRECTORY \"${fvs_dest_wrapper}\")
    file(CREATE_LINK ../../../${CMAKE_INSTALL_BINDIR}/colmap-fvs \"${fvs_dest_wrapper}/colmap\" SYMBOLIC)
    message(STATUS \"Installing link: ${fvs_dest_wrapper}/colmap -> ../../../${CMAKE_INSTALL_BINDIR}/colmap-fvs\")"
    COMPONENT runtime)
  install(FILES ${CMAKE_BINARY_DIR}/bin/.fvs_front_door DESTINATION lib/colmap-fvs/bin
          COMPONENT runtime)

  install(CODE "
    file(CREATE_LINK colmap-fvs \"${fvs_dest_bin}/colmap\" SYMBOLIC)
    message(STATUS \"Installing link: ${fvs_dest_bin}/colmap -> colmap-fvs\")"
    COMPONENT colmap_name)
  install(FILES ${CMAKE_BINARY_DIR}/bin/.fvs_front_door DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT colmap_name)

  install(FILES ${CMAKE_SOURCE_DIR}/doc/colmap-fvs.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
          COMPONENT runtime)
endif()
if(TARGET fvs_train_main)
  install(TARGETS fvs_train_main RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()

# Whatever models/ holds: weights, their cards, the README.
install(DIRECTORY ${CMAKE_SOURCE_DIR}/models/ DESTINATION ${FVS_INSTALL_SHARE_DIR}/models
        COMPONENT runtime
        FILES_MATCHING PATTERN "*.safetensors" PATTERN "*.json" PATTERN "*.md")
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION ${FVS_INSTALL_DOC_DIR} COMPONENT runtime)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/doc/ DESTINATION ${FVS_INSTALL_DOC_DIR}/doc
        COMPONENT runtime PATTERN "*.1" EXCLUDE)

# The Debian package: cpack -G DEB in the build folder -> colmap-fvs_<version>_<arch>.deb.
# Depends: what dpkg-shlibdeps derives from the installed binaries (LibTorch, OpenImageIO,
# Qt5, Ceres, glog, ...) plus COLMAP, which the front door runs rather than links.
set(CPACK_PACKAGE_NAME colmap-fvs)
set(CPACK_PACKAGE_VENDOR "colmap-fvs")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Free View Synthesis as a COLMAP extension: novel views from your photos")
set(CPACK_PACKAGE_DESCRIPTION
    "Photograph a place, calibrate the photos with COLMAP, build proxy geometry, then\n\
render images and fly-through videos from viewpoints nobody photographed. The front door\n\
colmap-fvs runs the view_synthesis* commands and hands every other command to COLMAP.")
set(CPACK_PACKAGE_CONTACT "colmap-fvs maintainers <colmap-fvs@invalid>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ALL_COMPONENTS_IN_ONE)
set(CPACK_COMPONENTS_ALL runtime)
set(CPACK_DEBIAN_PACKAGE_NAME colmap-fvs)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "colmap (>= 3.7)")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "ffmpeg")
include(CPack)
