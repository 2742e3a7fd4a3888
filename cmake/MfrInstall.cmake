# What `cmake --install` puts under the prefix, and the Debian package `cpack` builds from it
# (docs/install.md). Shaders and shipped data are embedded in the binaries, so an installation is
# the two programs, mfrview's plugins, the desktop entry, icon and MIME types, and the docs.
install(TARGETS mfr RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(MFR_BUILD_VIEWER)
  install(TARGETS mfrview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(TARGETS mfrview_budget mfrview_csg mfrview_ghosting mfrview_hybridvolume
          LIBRARY DESTINATION ${MFRVIEW_INSTALL_PLUGIN_DIR})
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/mfrview.desktop DESTINATION ${CMAKE_INSTALL_DATADIR}/applications)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/mfrview.svg
          DESTINATION ${CMAKE_INSTALL_DATADIR}/icons/hicolor/scalable/apps)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/mfr.xml DESTINATION ${CMAKE_INSTALL_DATADIR}/mime/packages)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)

# cpack --config build/CPackConfig.cmake -B DIR: DIR/mfr_VERSION_ARCH.deb. Its Depends are found by
# dpkg-shlibdeps from the binaries' libraries; the binaries are stripped (the build keeps its
# debug information).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME mfr)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "multifragment rendering: see through dense 3D data (mfr, mfrview)")
set(CPACK_PACKAGE_DESCRIPTION
    "mfr captures many fragments per pixel, sorts them and runs an operation on each pixel's list: exact and \
approximate order-independent transparency, hybrid transparency under a memory budget, image-space CSG, z-thickness \
blending and volumes composited with surfaces (OpenGL 4.5). mfr is the command line, mfrview the Qt 6 viewer.")
set(CPACK_PACKAGE_CONTACT "mfr maintainers <maintainers@mfr.invalid>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# libepoxy opens the GL and EGL libraries at run time, so dpkg-shlibdeps cannot see them.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libegl1, libgl1")
# Without a GPU driver, Mesa's llvmpipe renders (docs/install.md).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libgl1-mesa-dri")
include(CPack)
