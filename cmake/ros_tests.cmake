# The tests' writers of ROS recordings (tests/ros/): the ROS 1 one with the ROS bag storage
# library (an implementation independent of our reader), as C++17: the ROS 1 message headers
# use std::allocator<void>::rebind, which C++20 removed.
#
# WHEELINS_ROS1=OFF (a machine without Debian's ROS packages) builds no ROS 1 writer: the
# program is the same (it reads ROS 1 bags with its own reader), and the tests that need a
# bag written by the ROS library skip (WHEELINS_HAVE_ROS1).
#
# Debian 12's rosbag_storage CMake config pulls in ROS 2's pluginlib/ament machinery (and
# runs a Python module of it) and its pkg-config file names a pluginlib.pc that does not
# exist, so the headers and libraries are found directly.
if(WHEELINS_ROS1)
  set(_wheelins_ros1_hint "install the ROS 1 packages with scripts/setup.sh (librosbag-storage-dev, \
libsensor-msgs-dev, libnav-msgs-dev, libgeometry-msgs-dev, libtf2-msgs-dev), or configure with \
-DWHEELINS_ROS1=OFF to build without them")
  find_path(WHEELINS_ROSBAG_INCLUDE rosbag/bag.h)
  find_path(WHEELINS_IMU_MSG_INCLUDE sensor_msgs/Imu.h)
  find_path(WHEELINS_ODOM_MSG_INCLUDE nav_msgs/Odometry.h)
  find_path(WHEELINS_POSE_MSG_INCLUDE geometry_msgs/PoseStamped.h)
  find_path(WHEELINS_TF_MSG_INCLUDE tf2_msgs/TFMessage.h)
  # rosbag/bag.h includes pluginlib (for its encryption plugins), which Debian ships in the
  # ROS 2 layout include/<package>/<package>/.
  set(_wheelins_ros1_includes)
  foreach(pkg pluginlib class_loader rcpputils rcutils ament_index_cpp)
    find_path(WHEELINS_${pkg}_INCLUDE ${pkg} PATHS /usr/include/${pkg} NO_DEFAULT_PATH)
    list(APPEND _wheelins_ros1_includes ${WHEELINS_${pkg}_INCLUDE})
  endforeach()
  set(_wheelins_ros1_libs)
  foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge)
    find_library(WHEELINS_${lib}_LIB ${lib})
    list(APPEND _wheelins_ros1_libs ${WHEELINS_${lib}_LIB})
  endforeach()
  foreach(v WHEELINS_ROSBAG_INCLUDE WHEELINS_IMU_MSG_INCLUDE WHEELINS_ODOM_MSG_INCLUDE
            WHEELINS_POSE_MSG_INCLUDE WHEELINS_TF_MSG_INCLUDE _wheelins_ros1_includes _wheelins_ros1_libs)
    if(NOT ${v} OR "${${v}}" MATCHES "NOTFOUND")
      message(FATAL_ERROR "wheelins tests: ${v} not found; ${_wheelins_ros1_hint}")
    endif()
  endforeach()

  add_library(wheelins_test_ros1 STATIC ${CMAKE_SOURCE_DIR}/tests/ros/ros1_writer.cpp)
  set_target_properties(wheelins_test_ros1 PROPERTIES CXX_STANDARD 17)
  target_include_directories(wheelins_test_ros1 PRIVATE ${CMAKE_BINARY_DIR}/layers/io)
  target_include_directories(wheelins_test_ros1 SYSTEM PRIVATE ${WHEELINS_ROSBAG_INCLUDE} ${_wheelins_ros1_includes})
  target_link_libraries(wheelins_test_ros1 PRIVATE wheelins_warnings PUBLIC ${_wheelins_ros1_libs})
  target_link_libraries(wheelins_tests PRIVATE wheelins_test_ros1)
  target_compile_definitions(wheelins_tests PRIVATE WHEELINS_HAVE_ROS1=1)
else()
  target_compile_definitions(wheelins_tests PRIVATE WHEELINS_HAVE_ROS1=0)
endif()
target_sources(wheelins_tests PRIVATE ${CMAKE_SOURCE_DIR}/tests/ros/ros2_writers.cpp)
target_include_directories(wheelins_tests SYSTEM PRIVATE ${WHEELINS_ZSTD_INCLUDE} ${WHEELINS_LZ4_INCLUDE})
