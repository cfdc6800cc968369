# The tests' writers of ROS recordings (tests/ros/): the ROS 1 one with the ROS bag
# storage library, as C++17 like src/wheelins/io/ros/ros1_bag.cpp (cmake/ros.cmake).
add_library(wheelins_test_ros1 STATIC ${CMAKE_SOURCE_DIR}/tests/ros/ros1_writer.cpp)
set_target_properties(wheelins_test_ros1 PROPERTIES CXX_STANDARD 17)
target_include_directories(wheelins_test_ros1 PRIVATE ${CMAKE_BINARY_DIR}/layers/io)
target_include_directories(wheelins_test_ros1 SYSTEM PRIVATE ${WHEELINS_ROSBAG_INCLUDE} ${_wheelins_ros1_includes})
target_link_libraries(wheelins_test_ros1 PRIVATE wheelins_warnings PUBLIC ${_wheelins_ros1_libs})
target_sources(wheelins_tests PRIVATE ${CMAKE_SOURCE_DIR}/tests/ros/ros2_writers.cpp)
target_include_directories(wheelins_tests SYSTEM PRIVATE ${WHEELINS_ZSTD_INCLUDE} ${WHEELINS_LZ4_INCLUDE})
target_link_libraries(wheelins_tests PRIVATE wheelins_test_ros1)
