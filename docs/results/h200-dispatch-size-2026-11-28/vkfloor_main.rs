// Times what any Vulkan program pays before its first dispatch: loading
// the loader, vkCreateInstance, enumerating physical devices, and
// vkCreateDevice with one compute queue (no extensions, no features).
use std::time::Instant;
fn main() {
    let t0 = Instant::now();
    let entry = unsafe { ash::Entry::load().expect("libvulkan") };
    let t_load = t0.elapsed().as_secs_f64();
    let app = ash::vk::ApplicationInfo::default().api_version(ash::vk::API_VERSION_1_3);
    let info = ash::vk::InstanceCreateInfo::default().application_info(&app);
    let instance = unsafe { entry.create_instance(&info, None).expect("instance") };
    let t_inst = t0.elapsed().as_secs_f64();
    let pds = unsafe { instance.enumerate_physical_devices().expect("devices") };
    let pd = pds[0];
    let props = unsafe { instance.get_physical_device_properties(pd) };
    let name = props.device_name_as_c_str().unwrap().to_string_lossy().into_owned();
    let qf = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let family = qf.iter().position(|q| q.queue_flags.contains(ash::vk::QueueFlags::COMPUTE)).unwrap() as u32;
    let t_enum = t0.elapsed().as_secs_f64();
    let prio = [1.0f32];
    let qi = [ash::vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&prio)];
    let dinfo = ash::vk::DeviceCreateInfo::default().queue_create_infos(&qi);
    let device = unsafe { instance.create_device(pd, &dinfo, None).expect("device") };
    let t_dev = t0.elapsed().as_secs_f64();
    println!(
        "{name}: loader {:.3} s, instance {:.3} s, enumerate {:.3} s, device {:.3} s, total {:.3} s",
        t_load,
        t_inst - t_load,
        t_enum - t_inst,
        t_dev - t_enum,
        t_dev
    );
    unsafe {
        device.destroy_device(None);
        instance.destroy_instance(None);
    }
}
