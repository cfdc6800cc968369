# ROS recordings for `wheelins import` (src/wheelins/io/ros/): ROS 1 bags through the
# ROS bag storage library, ROS 2 bags in sqlite3 and MCAP (our readers, with zstd and
# lz4 for compressed MCAP chunks). All are Debian packages that scripts/setup.sh installs.
#
# Debian 12's rosbag_storage CMake config pulls in ROS 2's pluginlib/ament machinery (and
# runs a Python module of it) and its pkg-config file names a pluginlib.pc that does not
# exist, so the headers and libraries are found directly. The ROS 1 message headers do not
# compile as C++20 (std::allocator<void>::rebind), so the one file that includes them is a
# C++17 library of its own, behind the plain interface of io/ros/messages.hpp. It is part
# of the io layer: compiled against the io layer's include root (it sees math, nav and io
# only), and wheelins_io links it.
set(_wheelins_ros_hint "install the ROS packages with scripts/setup.sh (librosbag-storage-dev, \
libsensor-msgs-dev, libnav-msgs-dev, libgeometry-msgs-dev, libtf2-msgs-dev, libsqlite3-dev, \
libzstd-dev, liblz4-dev)")
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
find_package(SQLite3)
find_path(WHEELINS_ZSTD_INCLUDE zstd.h)
find_library(WHEELINS_ZSTD_LIB zstd)
find_path(WHEELINS_LZ4_INCLUDE lz4frame.h)
find_library(WHEELINS_LZ4_LIB lz4)
foreach(v WHEELINS_ROSBAG_INCLUDE WHEELINS_IMU_MSG_INCLUDE WHEELINS_ODOM_MSG_INCLUDE
          WHEELINS_POSE_MSG_INCLUDE WHEELINS_TF_MSG_INCLUDE _wheelins_ros1_includes _wheelins_ros1_libs
          WHEELINS_ZSTD_INCLUDE WHEELINS_ZSTD_LIB WHEELINS_LZ4_INCLUDE WHEELINS_LZ4_LIB)
  if(NOT ${v} OR "${${v}}" MATCHES "NOTFOUND")
    message(FATAL_ERROR "wheelins import: ${v} not found; ${_wheelins_ros_hint}")
  endif()
endforeach()
if(NOT SQLite3_FOUND)
  message(FATAL_ERROR "wheelins import: sqlite3 not found; ${_wheelins_ros_hint}")
endif()

add_library(wheelins_ros1 STATIC ${CMAKE_SOURCE_DIR}/src/wheelins/io/ros/ros1_bag.cpp)
set_target_properties(wheelins_ros1 PROPERTIES CXX_STANDARD 17)
target_include_directories(wheelins_ros1 PRIVATE ${CMAKE_BINARY_DIR}/layers/io)
target_include_directories(wheelins_ros1 SYSTEM PRIVATE ${WHEELINS_ROSBAG_INCLUDE} ${_wheelins_ros1_includes})
target_link_libraries(wheelins_ros1 PRIVATE wheelins_warnings wheelins_nav PUBLIC ${_wheelins_ros1_libs})

target_include_directories(wheelins_io SYSTEM PRIVATE ${WHEELINS_ZSTD_INCLUDE} ${WHEELINS_LZ4_INCLUDE})
target_link_libraries(wheelins_io PUBLIC wheelins_ros1 SQLite::SQLite3 ${WHEELINS_ZSTD_LIB} ${WHEELINS_LZ4_LIB})
