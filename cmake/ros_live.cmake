# The ROS 1 node of `wheelins live --ros` (app/ros/): roscpp and the message headers of
# Debian's ROS 1 packages (scripts/setup.sh), compiled as C++17 (the ROS 1 message headers use
# std::allocator<void>::rebind, which C++20 removed) into a plugin next to the program
# (libwheelins_ros1_node.so), which `live --ros` loads (dlopen) and sees through plain types
# (app/ros/ros1_node.hpp). The program itself links no ROS library in any build
# (RosFreeBuild.TheProgramLinksNothingOfRos): it runs where ROS is not installed. WHEELINS_ROS1=OFF
# builds no plugin and no `--ros`.
if(WHEELINS_ROS1)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(WHEELINS_ROSCPP IMPORTED_TARGET roscpp)
  find_path(WHEELINS_DIAG_MSG_INCLUDE diagnostic_msgs/DiagnosticArray.h)
  if(NOT WHEELINS_ROSCPP_FOUND OR NOT WHEELINS_DIAG_MSG_INCLUDE)
    message(FATAL_ERROR "wheelins live --ros: roscpp or diagnostic_msgs not found; install the ROS 1 packages with "
                        "scripts/setup.sh (libroscpp-dev, libdiagnostic-msgs-dev), or configure with "
                        "-DWHEELINS_ROS1=OFF to build without them")
  endif()
  add_library(wheelins_ros1_node MODULE ${CMAKE_SOURCE_DIR}/app/ros/ros1_node.cpp)
  set_target_properties(wheelins_ros1_node PROPERTIES CXX_STANDARD 17 CXX_VISIBILITY_PRESET hidden
                        LIBRARY_OUTPUT_DIRECTORY $<TARGET_FILE_DIR:wheelins>)
  target_link_libraries(wheelins_ros1_node PRIVATE wheelins_warnings PkgConfig::WHEELINS_ROSCPP)
  add_dependencies(wheelins wheelins_ros1_node)
  target_link_libraries(wheelins PRIVATE ${CMAKE_DL_LIBS})
  target_compile_definitions(wheelins PRIVATE WHEELINS_HAVE_ROS_LIVE=1)
else()
  target_compile_definitions(wheelins PRIVATE WHEELINS_HAVE_ROS_LIVE=0)
endif()

# The folder roslaunch finds the node in (ros/wheelins: package.xml, launch/, config/), with a
# link to the program: ROS_PACKAGE_PATH=<build>/ros roslaunch wheelins live.launch manifest:=...
if(WHEELINS_ROS1)
  file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/ros/wheelins)
  foreach(item package.xml launch config)
    file(CREATE_LINK ${CMAKE_SOURCE_DIR}/ros/wheelins/${item} ${CMAKE_BINARY_DIR}/ros/wheelins/${item} SYMBOLIC)
  endforeach()
  add_custom_command(TARGET wheelins POST_BUILD
                     COMMAND ${CMAKE_COMMAND} -E create_symlink $<TARGET_FILE:wheelins>
                             ${CMAKE_BINARY_DIR}/ros/wheelins/wheelins)
endif()
