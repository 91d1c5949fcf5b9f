include(CMakePackageConfigHelpers)
set(SNAG_EXPORT_TARGETS snag_lib)
install(TARGETS snag_lib EXPORT snagTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY lib/include/snag DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT snagTargets NAMESPACE snag:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/snag)
configure_package_config_file(cmake/snagConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/snagConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/snag)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/snagConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/snagConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/snagConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/snag)
