# Every find_package of the project lives here; targets link imported targets only.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres REQUIRED)
# CHOLMOD (SuiteSparse, which Ceres is built with): the supernodal Cholesky that `compare` solves a
# map's joint pose covariance with (mapping/slam/joint_pose_uncertainty.cpp).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
add_library(uwscan_cholmod INTERFACE IMPORTED)
target_include_directories(uwscan_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(uwscan_cholmod INTERFACE ${CHOLMOD_LIBRARY})
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs calib3d aruco surface_matching)
find_package(yaml-cpp REQUIRED)
find_package(LibXml2 REQUIRED)  # OpenCV calibration files in XML (scanner/calibration)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
if(UWSCAN_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# PCL: its component targets carry VTK, Qt and OpenNI in their link interface. uwscan links
# the component libraries themselves through one interface target, so that only the viewer
# links VTK (DESIGN.md, "Known traps").
find_package(PCL 1.13 REQUIRED COMPONENTS common io kdtree search features filters
             segmentation sample_consensus registration recognition)
add_library(uwscan_pcl INTERFACE)
target_include_directories(uwscan_pcl SYSTEM INTERFACE ${PCL_INCLUDE_DIRS})
foreach(component common io io_ply kdtree search octree features filters segmentation
                  sample_consensus registration recognition)
  find_library(UWSCAN_PCL_${component} pcl_${component} REQUIRED)
  target_link_libraries(uwscan_pcl INTERFACE ${UWSCAN_PCL_${component}})
endforeach()
target_link_libraries(uwscan_pcl INTERFACE Eigen3::Eigen FLANN::FLANN)

# Open3D is only a peer in the registration benchmark: built against when present.
find_package(Open3D QUIET)

# Meshes (PLY/OFF/STL/OBJ) for scenes and benchmark objects.
find_package(assimp REQUIRED)

# Ray casting in the simulator (scanner/sim).
find_package(embree 3 REQUIRED)

# Dive logs (mapping/log/dive_log), with a checksum per column of every row (xxHash's XXH3).
find_package(SQLite3 REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(xxhash REQUIRED IMPORTED_TARGET libxxhash)

# The viewer (viewer/), the one module that links VTK: component targets only, never
# ${VTK_LIBRARIES} (DESIGN.md, "Known traps"). X11 checks that a display answers before VTK
# opens one: VTK 9.1 on Debian 12 renders only through X and aborts the process without it.
find_package(VTK 9.1 REQUIRED COMPONENTS
  CommonCore CommonDataModel CommonColor FiltersCore FiltersSources IOImage
  RenderingCore RenderingOpenGL2 RenderingAnnotation RenderingFreeType
  InteractionStyle ChartsCore RenderingContext2D RenderingContextOpenGL2 ViewsContext2D)
find_package(X11 REQUIRED)
find_package(Threads REQUIRED)

# GenICam cameras (scanner/acquisition, the one part that links Aravis): Debian's aravis-0.8.
find_package(PkgConfig REQUIRED)
pkg_check_modules(Aravis REQUIRED IMPORTED_TARGET aravis-0.8)

# The ROS bag reader's chunk decompression (ros/bridge/bag_decompression: liblz4's frame API and
# libbz2, as rosbag compresses chunks). Outside the ROS block below: the fuzz build compiles the bag
# reader, which includes nothing of ROS, without ROS.
pkg_check_modules(lz4 REQUIRED IMPORTED_TARGET liblz4)
find_package(BZip2 REQUIRED)
add_library(uwscan_bag_compression INTERFACE)
target_link_libraries(uwscan_bag_compression INTERFACE PkgConfig::lz4 BZip2::BZip2)

# ROS 1 (ros/, the one module that links it). roscpp by its CMake config, which works without
# catkin. rosbag's config is not used: through pluginlib it loads ament_cmake_core, which runs a
# Python module (ament_package) that a non-Debian python3 first on the PATH lacks; rosbag's
# libraries and the nested include folders its bag.h needs (pluginlib, class_loader, ament,
# rcpputils, rcutils) are found directly. The message packages are header-only, in the system
# include path: find_package of them would pull catkin in (DESIGN.md, "Known traps").
if(NOT UWSCAN_LIBRARIES_ONLY)
  find_package(roscpp REQUIRED)
  add_library(uwscan_rosbag INTERFACE)
  foreach(library rosbag rosbag_storage class_loader ament_index_cpp console_bridge)
    find_library(UWSCAN_ROS_${library} ${library} REQUIRED)
    target_link_libraries(uwscan_rosbag INTERFACE ${UWSCAN_ROS_${library}})
  endforeach()
  foreach(header pluginlib/class_loader.hpp class_loader/class_loader.hpp
                 ament_index_cpp/get_package_prefix.hpp rcpputils/shared_library.hpp rcutils/types.h)
    get_filename_component(package ${header} DIRECTORY)
    find_path(UWSCAN_ROS_INCLUDE_${package} ${header} PATH_SUFFIXES ${package} REQUIRED)
    target_include_directories(uwscan_rosbag SYSTEM INTERFACE ${UWSCAN_ROS_INCLUDE_${package}})
  endforeach()
  target_include_directories(uwscan_rosbag SYSTEM INTERFACE ${roscpp_INCLUDE_DIRS})
  target_link_libraries(uwscan_rosbag INTERFACE ${roscpp_LIBRARIES})
endif()
